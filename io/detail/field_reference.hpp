#pragma once
// The scene-key reference generated from the field tables (core/detail/field_table.hpp): every
// table a scene reads, as Markdown (docs' reference page, `jelly fields`) or JSON
// (`jelly fields --format json`, the Python stub check).
#include <string>
#include <vector>

#include <jelly/core/detail/field_table.hpp>

namespace jelly {

// Every field table of a scene, in the order of docs/scenes.md.
std::vector<FieldTableDoc> scene_field_tables();
std::string field_tables_markdown(const std::vector<FieldTableDoc>& tables);
std::string field_tables_json(const std::vector<FieldTableDoc>& tables);

}  // namespace jelly
