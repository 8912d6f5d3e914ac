#include <jelly/solvers/integrators/registry.hpp>

#include <algorithm>
#include <string>
#include <utility>

#include <jelly/core/detail/json.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/detail/explicit_euler.hpp>
#include <jelly/solvers/integrators/detail/implicit_euler.hpp>
#include <jelly/solvers/integrators/detail/midpoint.hpp>
#include <jelly/solvers/integrators/detail/options_io.hpp>
#include <jelly/solvers/integrators/detail/projective_dynamics.hpp>
#include <jelly/solvers/integrators/detail/rk4.hpp>
#include <jelly/solvers/integrators/detail/symplectic_euler.hpp>
#include <jelly/solvers/integrators/detail/vbd.hpp>
#include <jelly/solvers/integrators/detail/xpbd.hpp>

namespace jelly {

namespace {

using detail::options_io;
constexpr auto kImplicit = &IntegratorOptions::implicit;
constexpr auto kPd = &IntegratorOptions::pd;
constexpr auto kXpbd = &IntegratorOptions::xpbd;
constexpr auto kVbd = &IntegratorOptions::vbd;

struct Entry {
  IntegratorInfo info;
  IntegratorFactory make;
};

const IntegratorOptionsIo kNoOptions{};

template <typename T>
IntegratorFactory plain() {
  return
      [](const IntegratorOptions&) -> std::unique_ptr<Integrator> { return std::make_unique<T>(); };
}

// The core's integrators; the components add theirs (register_integrator). Kept sorted by name.
std::vector<Entry>& table() {
  static std::vector<Entry> entries = [] {
    std::vector<Entry> e{
        {{"explicit_euler", "forward Euler, order 1, explicit", kNoOptions, true},
         plain<ExplicitEuler>()},
        {{"implicit_euler",
          "backward Euler on a sparse Cholesky/CG solver, order 1, implicit (stable at any dt)",
          options_io<kImplicit>()},
         [](const IntegratorOptions& o) -> std::unique_ptr<Integrator> {
           return std::make_unique<ImplicitEuler>(o.implicit);
         }},
        {{"midpoint", "explicit midpoint (the report's midpoint Euler), order 2", kNoOptions, true},
         plain<Midpoint>()},
        {{"projective_dynamics",
          "local/global backward Euler on one prefactored matrix (Liu 2013), order 1, implicit",
          options_io<kPd>()},
         [](const IntegratorOptions& o) -> std::unique_ptr<Integrator> {
           return std::make_unique<ProjectiveDynamics>(o.pd);
         }},
        {{"rk4", "classical Runge-Kutta, order 4, explicit", kNoOptions, true},
         plain<RungeKutta4>()},
        {{"symplectic_euler",
          "semi-implicit Euler, order 1 (what the report called implicit Euler)", kNoOptions, true},
         plain<SymplecticEuler>()},
        {{"vbd",
          "vertex block descent: per-particle 3x3 Newton steps of backward Euler in a graph "
          "colouring (Chen 2024), order 1, implicit",
          options_io<kVbd>()},
         [](const IntegratorOptions& o) -> std::unique_ptr<Integrator> {
           return std::make_unique<Vbd>(o.vbd);
         }},
        {{"xpbd", "extended position-based dynamics with substeps (Macklin 2016, 2019), order 1",
          options_io<kXpbd>()},
         [](const IntegratorOptions& o) -> std::unique_ptr<Integrator> {
           return std::make_unique<Xpbd>(o.xpbd);
         }},
    };
    std::sort(e.begin(), e.end(),
              [](const Entry& a, const Entry& b) { return a.info.name < b.info.name; });
    return e;
  }();
  return entries;
}

// The infos of table(), in its order: rebuilt when an integrator is registered.
std::vector<IntegratorInfo>& infos() {
  static std::vector<IntegratorInfo> out = [] {
    std::vector<IntegratorInfo> all;
    for (const Entry& e : table()) all.push_back(e.info);
    return all;
  }();
  return out;
}

}  // namespace

void register_integrator(const IntegratorInfo& info, IntegratorFactory make) {
  std::vector<Entry>& entries = table();
  const auto same = [&](const Entry& e) { return e.info.name == info.name; };
  if (std::any_of(entries.begin(), entries.end(), same)) return;
  entries.push_back({info, make});
  std::sort(entries.begin(), entries.end(),
            [](const Entry& a, const Entry& b) { return a.info.name < b.info.name; });
  std::vector<IntegratorInfo>& list = infos();
  list.clear();
  for (const Entry& e : entries) list.push_back(e.info);
}

const std::vector<IntegratorInfo>& integrator_infos() { return infos(); }

std::vector<std::string> integrator_names() {
  std::vector<std::string> names;
  for (const Entry& e : table()) names.emplace_back(e.info.name);
  return names;
}

bool integrator_supports_in_evaluation_contact(std::string_view name) {
  for (const IntegratorInfo& info : integrator_infos()) {
    if (info.name == name) return info.in_evaluation_contact;
  }
  return false;
}

const IntegratorInfo& find_integrator(std::string_view name, std::string_view field) {
  for (const IntegratorInfo& info : integrator_infos()) {
    if (info.name == name) return info;
  }
  std::string known;
  for (const Entry& e : table())
    known += (known.empty() ? "\"" : ", \"") + std::string(e.info.name) + "\"";
  throw InputError(field, "\"" + std::string(name) + "\"", "one of " + known);
}

IntegratorOptions read_integrator_options(std::string_view name, JsonFields& fields) {
  IntegratorOptions options;
  const IntegratorInfo& info = find_integrator(name);
  if (info.options.read) info.options.read(fields, options);
  return options;
}

Json integrator_options_json(std::string_view name, const IntegratorOptions& options) {
  const IntegratorInfo& info = find_integrator(name);
  return info.options.write ? info.options.write(options) : Json::object();
}

std::unique_ptr<Integrator> make_integrator(std::string_view name, const IntegratorOptions& options,
                                            std::string_view options_path) {
  for (const Entry& e : table()) {
    if (e.info.name == name) {
      if (e.info.options.validate) {
        e.info.options.validate(options, std::string(options_path) + ".");
      }
      return e.make(options);
    }
  }
  find_integrator(name);  // throws, naming the known integrators
  return nullptr;
}

}  // namespace jelly
