#include <jelly/solvers/integrators/registry.hpp>

#include <algorithm>
#include <functional>

#include <jelly/core/errors.hpp>
#include <jelly/solvers/arkode/arkode_dirk.hpp>
#include <jelly/solvers/arkode/arkode_erk.hpp>
#include <jelly/solvers/integrators/explicit_euler.hpp>
#include <jelly/solvers/integrators/implicit_euler.hpp>
#include <jelly/solvers/integrators/midpoint.hpp>
#include <jelly/solvers/integrators/rk4.hpp>
#include <jelly/solvers/integrators/symplectic_euler.hpp>

namespace jelly {

namespace {

using Factory = std::function<std::unique_ptr<Integrator>(const IntegratorOptions&)>;

struct Entry {
  IntegratorInfo info;
  Factory make;
};

template <typename T>
Factory plain() {
  return [](const IntegratorOptions&) { return std::make_unique<T>(); };
}

const std::vector<Entry>& table() {
  static const std::vector<Entry> entries = [] {
    std::vector<Entry> e{
        {{"arkode_dirk",
          "SUNDIALS ARKODE adaptive implicit DIRK (Newton, Schur or KLU linear solves)"},
         [](const IntegratorOptions& o) { return std::make_unique<ArkodeDirk>(o.arkode); }},
        {{"arkode_erk", "SUNDIALS ARKODE adaptive explicit Runge-Kutta (default 5(4) pair)"},
         [](const IntegratorOptions& o) { return std::make_unique<ArkodeErk>(o.arkode); }},
        {{"explicit_euler", "forward Euler, order 1, explicit"}, plain<ExplicitEuler>()},
        {{"implicit_euler",
          "backward Euler on a sparse Cholesky/CG solver, order 1, implicit (stable at any dt)"},
         [](const IntegratorOptions& o) { return std::make_unique<ImplicitEuler>(o.implicit); }},
        {{"midpoint", "explicit midpoint (the report's midpoint Euler), order 2"},
         plain<Midpoint>()},
        {{"rk4", "classical Runge-Kutta, order 4, explicit"}, plain<RungeKutta4>()},
        {{"symplectic_euler",
          "semi-implicit Euler, order 1 (what the report called implicit Euler)"},
         plain<SymplecticEuler>()},
    };
    std::sort(e.begin(), e.end(),
              [](const Entry& a, const Entry& b) { return a.info.name < b.info.name; });
    return e;
  }();
  return entries;
}

}  // namespace

const std::vector<IntegratorInfo>& integrator_infos() {
  static const std::vector<IntegratorInfo> infos = [] {
    std::vector<IntegratorInfo> out;
    for (const Entry& e : table()) out.push_back(e.info);
    return out;
  }();
  return infos;
}

std::vector<std::string> integrator_names() {
  std::vector<std::string> names;
  for (const Entry& e : table()) names.emplace_back(e.info.name);
  return names;
}

std::unique_ptr<Integrator> make_integrator(std::string_view name,
                                            const IntegratorOptions& options) {
  for (const Entry& e : table()) {
    if (e.info.name == name) {
      options.validate();
      return e.make(options);
    }
  }
  std::string known;
  for (const Entry& e : table()) known += (known.empty() ? "" : ", ") + std::string(e.info.name);
  throw InputError("integrator.name: unknown integrator '" + std::string(name) +
                   "'. Known: " + known);
}

}  // namespace jelly
