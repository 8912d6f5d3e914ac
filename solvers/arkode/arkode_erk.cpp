#include <jelly/solvers/arkode/detail/arkode_erk.hpp>

#include <arkode/arkode_butcher_erk.h>
#include <arkode/arkode_erkstep.h>

#include <jelly/core/errors.hpp>
#include <jelly/solvers/arkode/detail/arkode_support.hpp>

namespace jelly {

namespace {

class ErkDriver final : public arkode::Driver {
 public:
  ErkDriver(const ArkodeOptions& options, std::string method)
      : Driver("arkode_erk", arkode::kErkStepApi, options), method_(std::move(method)) {}

 protected:
  int create(realtype t0, N_Vector y0) override {
    memory_.reset(ERKStepCreate(arkode::rhs, t0, y0, context_.get()));
    if (!memory_) return ARK_MEM_FAIL;
    int flag = ERKStepSetErrHandlerFn(memory_.get(), arkode::keep_error, &data_);
    if (flag >= 0) flag = ERKStepSetTableName(memory_.get(), method_.c_str());
    return flag;
  }

  arkode::Counters read_counters() const override {
    arkode::Counters c = Driver::read_counters();
    ERKStepGetNumRhsEvals(memory_.get(), &c.rhs_evaluations);
    return c;
  }

 private:
  std::string method_;
};

}  // namespace

ArkodeErk::ArkodeErk(const ArkodeOptions& options) {
  options.validate("ArkodeOptions.");
  const std::string method = options.method.empty() ? kDefaultMethod : options.method;
  const int id = arkode_method_id(arkode_erk_methods(), method, kDefaultMethod);
  ARKodeButcherTable table = ARKodeButcherTable_LoadERK(static_cast<ARKODE_ERKTableID>(id));
  const bool embedded = table != nullptr && table->d != nullptr;
  if (table != nullptr) {
    order_ = table->q;
    stages_ = table->stages;
    ARKodeButcherTable_Free(table);
  }
  require(embedded, "integrator.options.method", method,
          "an explicit table of ARKODE with an embedding");
  driver_ = std::make_unique<ErkDriver>(options, method);
}

ArkodeErk::~ArkodeErk() = default;

StepResult ArkodeErk::do_step(const Dynamics& dynamics, State& state, Real h) {
  return driver_->advance(dynamics, state, h);
}

Statistics ArkodeErk::statistics() const {
  Statistics s = driver_->statistics();
  for (const auto& [key, value] : Integrator::statistics()) s[key] = value;
  return s;
}

}  // namespace jelly
