#include <jelly/io/detail/field_reference.hpp>

#include <jelly/core/detail/json.hpp>
#include <jelly/geometry/detail/body_shape_fields.hpp>
#include <jelly/io/detail/scene_fields.hpp>
#include <jelly/solvers/contact/detail/body_contact_fields.hpp>
#include <jelly/solvers/detail/run_fields.hpp>
#include <jelly/solvers/integrators/detail/option_fields.hpp>
#include <jelly/terrain/detail/contact_fields.hpp>
#include <jelly/terrain/detail/terrain_fields.hpp>

namespace jelly {

std::vector<FieldTableDoc> scene_field_tables() {
  std::vector<FieldTableDoc> tables{
      document_fields(scene_fields()),
      document_fields(integrator_spec_fields()),
      document_fields(implicit_euler_fields(), {"implicit_euler"}),
      document_fields(projective_dynamics_fields(), {"projective_dynamics"}),
      document_fields(xpbd_fields(), {"xpbd"}),
      document_fields(vbd_fields(), {"vbd"}),
      document_fields(body_fields()),
      document_fields(spring_fields()),
      document_fields(pin_fields()),
      document_fields(external_force_fields(ExternalForceKind::kConstant), {"constant"}),
      document_fields(external_force_fields(ExternalForceKind::kPoint), {"point"}),
      document_fields(external_force_fields(ExternalForceKind::kWind), {"wind"}),
      document_fields(cube_shape_fields(), {"cube"}),
      document_fields(box_shape_fields(), {"box"}),
      document_fields(cloth_shape_fields(), {"cloth"}),
      document_fields(voxelized_shape_fields(), {"voxelized"}),
      document_fields(tetmesh_shape_fields(), {"tetmesh"}),
      document_fields(plane_fields(), {"plane"}),
      document_fields(slope_fields(), {"slope"}),
      document_fields(elevator_fields(), {"elevator"}),
      document_fields(obstacle_fields(ObstacleShape::kSphere), {"sphere"}),
      document_fields(obstacle_fields(ObstacleShape::kBox), {"box"}),
      document_fields(obstacle_fields(ObstacleShape::kCapsule), {"capsule"}),
      document_fields(obstacle_fields(ObstacleShape::kCylinder), {"cylinder"}),
      document_fields(mesh_obstacle_fields(), {"mesh"}),
      document_fields(contact_params_fields()),
      document_fields(body_contact_fields()),
      document_fields(divergence_fields()),
      document_fields(crush_fields()),
  };
  for (const FieldTableDocument document : component_field_documents())
    tables.push_back(document());
  return tables;
}

namespace {

// A Markdown table cell: pipes escaped, code spans for JSON values.
std::string cell(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::string used_by_text(const FieldTableDoc& t) {
  std::string out;
  for (std::size_t i = 0; i < t.used_by.size(); ++i)
    out += (i == 0 ? "" : i + 1 == t.used_by.size() ? " and " : ", ") + ("`" + t.used_by[i] + "`");
  return out;
}

}  // namespace

std::string field_tables_markdown(const std::vector<FieldTableDoc>& tables) {
  std::string out;
  for (const FieldTableDoc& t : tables) {
    out += t.path.empty() ? std::string("## The top level") : "## `" + t.path + "`";
    if (!t.used_by.empty()) out += " of " + used_by_text(t);
    out += "\n\n" + t.title + "; C++ type `" + t.name + "`.\n\n";
    out += "| key | type | default | unit | allowed | what |\n|---|---|---|---|---|---|\n";
    for (const FieldDoc& f : t.fields) {
      const std::string fallback = f.required   ? std::string("required")
                                   : f.optional ? std::string("none")
                                   : f.type == "object" || f.type == "list"
                                       ? std::string("")
                                       : "`" + cell(f.default_text) + "`";
      out += "| `" + f.name + "` | " + f.type + " | " + fallback + " | " + cell(f.unit) + " | " +
             cell(f.allowed) + " | " + cell(f.help) + " |\n";
    }
    out += "\n";
  }
  return out;
}

std::string field_tables_json(const std::vector<FieldTableDoc>& tables) {
  Json out = Json::array();
  for (const FieldTableDoc& t : tables) {
    Json fields = Json::array();
    for (const FieldDoc& f : t.fields) {
      Json j = {{"name", f.name},
                {"type", f.type},
                {"default", Json::parse(f.default_text)},
                {"unit", f.unit},
                {"allowed", f.allowed},
                {"help", f.help},
                {"constrained", f.constrained},
                {"required", f.required}};
      if (!f.example.empty()) j["example"] = Json::parse(f.example);
      if (f.per_component) j["per_component"] = true;
      if (f.type == "integer" || f.type == "number") {
        Json range = Json::object();
        if (std::isfinite(f.range.lo)) range["min"] = f.range.lo;
        if (std::isfinite(f.range.hi)) range["max"] = f.range.hi;
        range["min_open"] = f.range.lo_open;
        range["max_open"] = f.range.hi_open;
        range["or_zero"] = f.range.or_zero;
        j["range"] = range;
      }
      if (!f.choices.empty()) j["choices"] = f.choices;
      fields.push_back(j);
    }
    out.push_back({{"name", t.name},
                   {"path", t.path},
                   {"title", t.title},
                   {"used_by", t.used_by},
                   {"fields", fields}});
  }
  return out.dump(2) + "\n";
}

}  // namespace jelly
