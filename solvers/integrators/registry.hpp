#pragma once
// Integrators by name, from one sorted table.
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <jelly/solvers/integrators/integrator.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly {

struct IntegratorInfo {
  std::string_view name;
  std::string_view description;
};

// Every registered integrator, sorted by name.
const std::vector<IntegratorInfo>& integrator_infos();
std::vector<std::string> integrator_names();
// Throws InputError "Unknown integrator 'rk5'. Known: ..." for an unknown name.
std::unique_ptr<Integrator> make_integrator(std::string_view name,
                                            const IntegratorOptions& options = {});

}  // namespace jelly
