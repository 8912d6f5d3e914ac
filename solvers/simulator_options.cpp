// SimulatorOptions' field table and validation (solvers/detail/run_fields.hpp).
#include <jelly/solvers/simulator.hpp>

#include <jelly/core/detail/json.hpp>
#include <jelly/solvers/detail/run_fields.hpp>

namespace jelly {

const FieldTable<SimulatorOptions>& simulator_options_fields() {
  using O = SimulatorOptions;
  static const FieldTable<O> table = [] {
    FieldTable<O> t{
        "SimulatorOptions",
        "",
        "A simulator's settings (a scene gives dt under integrator, the others at its top)",
        {
            time_step_field<&O::dt>(),
            output_interval_field<&O::output_interval>(),
            threads_field<&O::threads>(),
            object_field<O>(
                "divergence", FieldType::kObject, "a DivergenceGuard",
                "What counts as diverged (its own table)", R"({"max_speed": 100.0})",
                [](JsonFields& f, O& o, std::string_view key) {
                  if (const Json* d = f.value(key)) {
                    JsonFields g(*d, f.path(key));
                    read_fields(divergence_fields(), g, o.divergence, g.prefix(), true);
                  }
                },
                [](const O& o, Json& j, std::string_view key) {
                  j[std::string(key)] = Json::object();
                  write_fields(divergence_fields(), o.divergence, j[std::string(key)]);
                }),
            object_field<O>(
                "crush", FieldType::kObject, "CrushLimits",
                "When a run's end names a crushed body (its own table)",
                R"({"min_volume_ratio": 0.5, "max_inverted_fraction": 0.1})",
                [](JsonFields& f, O& o, std::string_view key) {
                  if (const Json* c = f.value(key)) {
                    JsonFields g(*c, f.path(key));
                    read_fields(crush_fields(), g, o.crush, g.prefix(), true);
                  }
                },
                [](const O& o, Json& j, std::string_view key) {
                  j[std::string(key)] = Json::object();
                  write_fields(crush_fields(), o.crush, j[std::string(key)]);
                }),
        },
        // The objects' own fields.
        [](const O& o, const std::string&) {
          o.divergence.validate();
          o.crush.validate();
        },
    };
    t.fields[0].scene_key = "integrator.dt";
    return t;
  }();
  return table;
}

void SimulatorOptions::validate() const { validate_fields(simulator_options_fields(), *this, ""); }

}  // namespace jelly
