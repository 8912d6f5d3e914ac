#include <jelly/core/components.hpp>

#include <algorithm>

namespace jelly {

namespace {

std::vector<ComponentInfo>& registered() {
  static std::vector<ComponentInfo> list{
      {"core",
       "model, forces, terrains, contact, integrators, simulator (Eigen, CHOLMOD, OpenMP)"}};
  return list;
}

}  // namespace

std::vector<ComponentInfo> components() { return registered(); }

bool has_component(std::string_view name) {
  const std::vector<ComponentInfo>& list = registered();
  return std::any_of(list.begin(), list.end(),
                     [&](const ComponentInfo& c) { return c.name == name; });
}

void register_component(const ComponentInfo& info) {
  if (!has_component(info.name)) registered().push_back(info);
}

}  // namespace jelly
