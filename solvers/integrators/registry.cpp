#include <jelly/solvers/integrators/registry.hpp>

#include <algorithm>
#include <functional>
#include <string>
#include <type_traits>
#include <utility>

#include <jelly/core/errors.hpp>
#include <jelly/core/json.hpp>
#include <jelly/solvers/arkode/arkode_dirk.hpp>
#include <jelly/solvers/arkode/arkode_erk.hpp>
#include <jelly/solvers/integrators/explicit_euler.hpp>
#include <jelly/solvers/integrators/implicit_euler.hpp>
#include <jelly/solvers/integrators/midpoint.hpp>
#include <jelly/solvers/integrators/projective_dynamics.hpp>
#include <jelly/solvers/integrators/rk4.hpp>
#include <jelly/solvers/integrators/symplectic_euler.hpp>
#include <jelly/solvers/integrators/vbd.hpp>
#include <jelly/solvers/integrators/xpbd.hpp>

namespace jelly {

namespace {

using Factory = std::function<std::unique_ptr<Integrator>(const IntegratorOptions&)>;

// The options member `Member` of IntegratorOptions, read, written and validated by its own type.
template <auto Member>
IntegratorOptionsIo options_io() {
  using Options = std::remove_reference_t<decltype(std::declval<IntegratorOptions&>().*Member)>;
  IntegratorOptionsIo io;
  io.read = [](JsonFields& f, IntegratorOptions& o) { o.*Member = Options::read(f); };
  io.write = [](const IntegratorOptions& o) { return (o.*Member).to_json(); };
  io.validate = [](const IntegratorOptions& o, const std::string& prefix) {
    (o.*Member).validate(prefix);
  };
  return io;
}
constexpr auto kImplicit = &IntegratorOptions::implicit;
constexpr auto kArkode = &IntegratorOptions::arkode;
constexpr auto kPd = &IntegratorOptions::pd;
constexpr auto kXpbd = &IntegratorOptions::xpbd;
constexpr auto kVbd = &IntegratorOptions::vbd;

// arkode_erk's options: ArkodeOptions without arkode_dirk's linear solver.
IntegratorOptionsIo arkode_erk_options() {
  IntegratorOptionsIo io = options_io<kArkode>();
  io.validate = [](const IntegratorOptions& o, const std::string& prefix) {
    o.arkode.validate(prefix);
    require(o.arkode.linear_solver == ArkodeLinearSolver::kAuto, prefix + "linear_solver",
            "\"" + std::string(name_of(arkode_linear_solvers(), o.arkode.linear_solver)) + "\"",
            "\"auto\" (arkode_erk solves no linear system: linear_solver is arkode_dirk's "
            "option)");
  };
  return io;
}

struct Entry {
  IntegratorInfo info;
  Factory make;
};

const IntegratorOptionsIo kNoOptions{};

template <typename T>
Factory plain() {
  return [](const IntegratorOptions&) { return std::make_unique<T>(); };
}

const std::vector<Entry>& table() {
  static const std::vector<Entry> entries = [] {
    std::vector<Entry> e{
        {{"arkode_dirk",
          "SUNDIALS ARKODE adaptive implicit DIRK (Newton, Schur or KLU linear solves)",
          options_io<kArkode>()},
         [](const IntegratorOptions& o) { return std::make_unique<ArkodeDirk>(o.arkode); }},
        {{"arkode_erk", "SUNDIALS ARKODE adaptive explicit Runge-Kutta (default 5(4) pair)",
          arkode_erk_options()},
         [](const IntegratorOptions& o) { return std::make_unique<ArkodeErk>(o.arkode); }},
        {{"explicit_euler", "forward Euler, order 1, explicit", kNoOptions, true},
         plain<ExplicitEuler>()},
        {{"implicit_euler",
          "backward Euler on a sparse Cholesky/CG solver, order 1, implicit (stable at any dt)",
          options_io<kImplicit>()},
         [](const IntegratorOptions& o) { return std::make_unique<ImplicitEuler>(o.implicit); }},
        {{"midpoint", "explicit midpoint (the report's midpoint Euler), order 2", kNoOptions, true},
         plain<Midpoint>()},
        {{"projective_dynamics",
          "local/global backward Euler on one prefactored matrix (Liu 2013), order 1, implicit",
          options_io<kPd>()},
         [](const IntegratorOptions& o) { return std::make_unique<ProjectiveDynamics>(o.pd); }},
        {{"rk4", "classical Runge-Kutta, order 4, explicit", kNoOptions, true},
         plain<RungeKutta4>()},
        {{"symplectic_euler",
          "semi-implicit Euler, order 1 (what the report called implicit Euler)", kNoOptions, true},
         plain<SymplecticEuler>()},
        {{"vbd",
          "vertex block descent: per-particle 3x3 Newton steps of backward Euler in a graph "
          "colouring (Chen 2024), order 1, implicit",
          options_io<kVbd>()},
         [](const IntegratorOptions& o) { return std::make_unique<Vbd>(o.vbd); }},
        {{"xpbd", "extended position-based dynamics with substeps (Macklin 2016, 2019), order 1",
          options_io<kXpbd>()},
         [](const IntegratorOptions& o) { return std::make_unique<Xpbd>(o.xpbd); }},
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
