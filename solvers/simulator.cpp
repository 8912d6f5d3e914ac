#include <jelly/solvers/simulator.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

#include <jelly/core/detail/parallel.hpp>
#include <jelly/core/detail/spring_bands.hpp>
#include <jelly/core/detail/team_chooser.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/contact/detail/body_contact.hpp>
#include <jelly/solvers/contact/detail/contact_solver.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly {

// SimulatorOptions::validate: simulator_options.cpp (its field table).

Simulator::Simulator(Model model, State state, std::unique_ptr<Integrator> integrator,
                     SimulatorOptions options)
    : model_(std::move(model)),
      state_(std::move(state)),
      integrator_(std::move(integrator)),
      options_(options),
      contacts_(std::make_unique<ContactSolver>()),
      body_contact_(std::make_unique<BodyContact>()) {
  model_.validate();
  options_.validate();
  bands_ = std::make_unique<const SpringBands>(model_);
  require(integrator_ != nullptr, "integrator", "null", "an integrator");
  require(state_.x.size() == model_.num_dofs() && state_.v.size() == model_.num_dofs(),
          "state.x.size", state_.x.size(), "3 x the number of particles");
  require(std::isfinite(state_.t), "state.t", state_.t, "a finite time");
  next_output_ = state_.t;
}

Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;
Simulator& Simulator::operator=(Simulator&&) noexcept = default;

const ContactSolver& Simulator::contacts() const { return *contacts_; }
const BodyContact& Simulator::body_contact() const { return *body_contact_; }

void Simulator::check_terrain(const Terrain* terrain, size_t index) const {
  require(terrain != nullptr, "terrain", "null", "a terrain");
  if (terrain_contact_model(*terrain).acts_in_evaluation() &&
      !integrator_supports_in_evaluation_contact(integrator_->name())) {
    throw InputError("terrains[" + std::to_string(index) + "].contact.model", "\"seed_framework\"",
                     in_evaluation_contact_requirement(integrator_->name()));
  }
}

void Simulator::check_terrain_index(int index) const {
  require(index >= 0 && index < static_cast<int>(terrains_.size()), "terrain index", index,
          "an index in [0, " + std::to_string(terrains_.size()) + ")");
}

void Simulator::add_terrain(std::unique_ptr<Terrain> terrain) {
  check_terrain(terrain.get(), terrains_.size());
  terrains_.push_back(std::move(terrain));
}

void Simulator::remove_terrain(int index) {
  check_terrain_index(index);
  terrains_.erase(terrains_.begin() + index);
  // Seed contacts name no terrain; implicit_euler's carried contacts follow their terrain to
  // its new index (ImplicitContact::renumber_terrains).
}

void Simulator::replace_terrain(int index, std::unique_ptr<Terrain> terrain) {
  check_terrain_index(index);
  check_terrain(terrain.get(), static_cast<size_t>(index));
  terrains_[static_cast<size_t>(index)] = std::move(terrain);
}

ForceHandle Simulator::add_force(std::shared_ptr<Force> force) {
  require(force != nullptr, "force", "null", "a force");
  force->validate(model_.num_particles());
  forces_.push_back(std::move(force));
  force_handles_.push_back(next_force_handle_);
  return next_force_handle_++;
}

bool Simulator::remove_force(ForceHandle handle) {
  const auto at = std::find(force_handles_.begin(), force_handles_.end(), handle);
  if (at == force_handles_.end()) return false;
  const auto k = at - force_handles_.begin();
  forces_.erase(forces_.begin() + k);
  force_handles_.erase(at);
  return true;
}

namespace {
std::string body_field(const Model& model, int body) {
  require(body >= 0 && body < model.num_bodies(), "body", body,
          "a body index in [0, " + std::to_string(model.num_bodies()) + ")");
  return "bodies[" + std::to_string(body) + "].";
}
}  // namespace

void Simulator::set_spring_coefficients(int body, SpringType type, SpringCoefficients c) {
  const std::string at =
      body_field(model_, body) + "springs." + std::string(spring_type_name(type)) + ".";
  require(std::isfinite(c.ks) && c.ks >= 0, at + "ks", c.ks, "a finite stiffness >= 0 N/m");
  require(std::isfinite(c.kd) && c.kd >= 0, at + "kd", c.kd, "a finite damping >= 0 N s/m");
  const Body& b = model_.bodies[body];
  Springs& springs = model_.springs;
  for (int s = b.first_spring; s < b.end_spring(); ++s) {
    if (springs.type[s] != type) continue;
    springs.ks[s] = c.ks;
    springs.kd[s] = c.kd;
  }
  model_changed();
}

void Simulator::set_gravity(const Vec3& gravity) {
  require(gravity.allFinite(), "gravity", gravity.transpose(), "finite components (m/s^2)");
  model_.gravity = gravity;
  model_changed();
}

void Simulator::set_particle_mass(int body, Real particle_mass) {
  const std::string at = body_field(model_, body) + "particle_mass";
  require(std::isfinite(particle_mass) && particle_mass > 0, at, particle_mass,
          "a finite mass > 0 kg");
  const Body& b = model_.bodies[body];
  model_.mass.segment(b.first_particle, b.num_particles).setConstant(particle_mass);
  model_changed();
}

void Simulator::set_integrator(std::unique_ptr<Integrator> integrator) {
  require(integrator != nullptr, "integrator", "null", "an integrator");
  for (std::size_t k = 0; k < terrains_.size(); ++k) {
    if (terrain_contact_model(*terrains_[k]).acts_in_evaluation() &&
        !integrator_supports_in_evaluation_contact(integrator->name())) {
      throw InputError("terrains[" + std::to_string(k) + "].contact.model", "\"seed_framework\"",
                       in_evaluation_contact_requirement(integrator->name()));
    }
  }
  integrator_ = std::move(integrator);
}

void Simulator::set_dt(Real dt) {
  SimulatorOptions o = options_;
  o.dt = dt;
  o.validate();
  options_ = o;
}

void Simulator::set_output_interval(Real interval) {
  SimulatorOptions o = options_;
  o.output_interval = interval;
  o.validate();
  options_ = o;
  next_output_ = state_.t;  // the next frame now, then every interval
}

namespace {
void require_particle(const Model& model, int particle) {
  require(particle >= 0 && particle < model.num_particles(), "pin particle", particle,
          "a particle index in [0, " + std::to_string(model.num_particles()) + ")");
}
}  // namespace

void Simulator::set_pin(int particle, const Vec3& anchor, Path path) {
  require_particle(model_, particle);
  require(anchor.allFinite(), "pin anchor", anchor.transpose(), "finite components (m)");
  model_.pins.set(particle, anchor, std::move(path));
}

void Simulator::set_pin_target(int particle, const Vec3& position, const Vec3& velocity) {
  require_particle(model_, particle);
  require(model_.pins.find(particle) >= 0, "pin particle", particle,
          "a pinned particle (set_pin pins one)");
  require(position.allFinite(), "pin target", position.transpose(), "finite components (m)");
  require(velocity.allFinite(), "pin target velocity", velocity.transpose(),
          "finite components (m/s)");
  // position + velocity (t - now) = anchor + velocity t with anchor = position - velocity now.
  model_.pins.set(particle, position - velocity * state_.t, Path::linear(velocity));
}

bool Simulator::remove_pin(int particle) { return model_.pins.remove(particle); }

void Simulator::model_changed() {
  ++model_revision_;
  bands_ = std::make_unique<const SpringBands>(model_);
  for (const std::shared_ptr<Force>& force : forces_) force->validate(model_.num_particles());
}

void Simulator::set_body_contact(const BodyContactParams& params) {
  *body_contact_ = BodyContact(params);
}

void Simulator::check_no_overlap() { body_contact_->check_no_overlap(model_, state_.x); }

void Simulator::set_threads(int threads) {
  require(threads >= 0, "threads", threads, "an integer >= 0 (0 = all cores)");
  options_.threads = threads;
  team_.reset();
}

Observer::~Observer() {
  // forget() edits lists_ of this observer too: iterate over a copy.
  const std::vector<ObserverList*> lists = lists_;
  for (ObserverList* list : lists) list->forget(this);
}

void Observer::leave_simulators() {
  // remove() edits lists_ of this observer too: iterate over a copy. A list that shared the
  // observer's ownership may destroy it, which removes it from the other lists by itself (the
  // next remove() then finds nothing).
  const std::vector<ObserverList*> lists = lists_;
  for (ObserverList* list : lists) list->remove(*this);
}

ObserverList::ObserverList(ObserverList&& other) noexcept
    : observers_(std::move(other.observers_)), owned_(std::move(other.owned_)) {
  other.observers_.clear();
  other.owned_.clear();
  relink(&other);
}

ObserverList& ObserverList::operator=(ObserverList&& other) noexcept {
  if (this == &other) return *this;
  clear();
  observers_ = std::move(other.observers_);
  owned_ = std::move(other.owned_);
  other.observers_.clear();
  other.owned_.clear();
  relink(&other);
  return *this;
}

ObserverList::~ObserverList() { clear(); }

void ObserverList::relink(ObserverList* from) {
  for (Observer* o : observers_) {
    if (o == nullptr) continue;
    std::replace(o->lists_.begin(), o->lists_.end(), from, this);
  }
}

void ObserverList::clear() {
  for (Observer* o : observers_) {
    if (o == nullptr) continue;
    o->lists_.erase(std::remove(o->lists_.begin(), o->lists_.end(), this), o->lists_.end());
  }
  observers_.clear();
  // Owned observers are released last: their destructors no longer find this list.
  owned_.clear();
}

void ObserverList::add(Observer& observer) {
  if (std::find(observers_.begin(), observers_.end(), &observer) != observers_.end()) return;
  observers_.push_back(&observer);
  observer.lists_.push_back(this);
}

void ObserverList::add(std::shared_ptr<Observer> observer) {
  add(*observer);
  if (std::find(owned_.begin(), owned_.end(), observer) == owned_.end())
    owned_.push_back(std::move(observer));
}

bool ObserverList::remove(const Observer& observer) {
  const auto at = std::find(observers_.begin(), observers_.end(), &observer);
  if (at == observers_.end()) return false;
  Observer* o = *at;
  if (iterating_ > 0)
    *at = nullptr;
  else
    observers_.erase(at);
  o->lists_.erase(std::remove(o->lists_.begin(), o->lists_.end(), this), o->lists_.end());
  // Released last (this may destroy the observer, whose destructor then finds no list).
  const auto owned = std::find_if(owned_.begin(), owned_.end(),
                                  [&](const std::shared_ptr<Observer>& p) { return p.get() == o; });
  if (owned != owned_.end()) {
    std::shared_ptr<Observer> keep = std::move(*owned);
    owned_.erase(owned);
  }
  return true;
}

std::size_t ObserverList::size() const {
  return static_cast<std::size_t>(std::count_if(observers_.begin(), observers_.end(),
                                                [](Observer* o) { return o != nullptr; }));
}

void ObserverList::forget(const Observer* observer) {
  const auto at = std::find(observers_.begin(), observers_.end(), observer);
  if (at == observers_.end()) return;
  if (iterating_ > 0)
    *at = nullptr;
  else
    observers_.erase(at);
}

void Simulator::add_observer(Observer& observer) {
  observer.check_simulator(*this);
  observers_.add(observer);
}

void Simulator::add_observer(std::shared_ptr<Observer> observer) {
  require(observer != nullptr, "observer", "null", "an observer");
  observer->check_simulator(*this);
  observers_.add(std::move(observer));
}

bool Simulator::remove_observer(const Observer& observer) { return observers_.remove(observer); }

void Simulator::set_anchors(AnchorSprings anchors) {
  validate_anchors(anchors, model_.num_particles());
  anchors_ = std::move(anchors);
}

namespace {
// Copies into the existing buffers (same sizes), so that they keep their address.
void assign_state(State& to, const State& from) {
  to.t = from.t;
  to.x = from.x;
  to.v = from.v;
}
}  // namespace

void Simulator::set_state(State state) {
  require(state.x.size() == model_.num_dofs() && state.v.size() == model_.num_dofs(),
          "state.x.size", state.x.size(), "3 x the number of particles");
  assign_state(state_, state);
  contacts_->clear();
  next_output_ = state_.t;
  frames_ = 0;
}

SimulatorSnapshot Simulator::snapshot() const {
  SimulatorSnapshot s{state_,
                      contacts_->seed_contacts(),
                      contacts_->contact_count(),
                      total_steps_,
                      next_output_,
                      integrator_->internal_state(),
                      std::nullopt};
  if (model_revision_ > 0)
    s.model_values =
        ModelValues{model_.springs.ks, model_.springs.kd, model_.mass, model_.gravity, model_.pins};
  return s;
}

void Simulator::restore(SimulatorSnapshot snapshot) {
  State& s = snapshot.state;
  require(s.x.size() == model_.num_dofs() && s.v.size() == model_.num_dofs(),
          "snapshot.state.x.size", s.x.size(), "3 x the number of particles");
  require(std::isfinite(s.t), "snapshot.state.t", s.t, "a finite time");
  require(std::isfinite(snapshot.next_output), "snapshot.next_output", snapshot.next_output,
          "a finite time");
  require(snapshot.total_steps >= 0 && snapshot.total_steps <= SimulatorSnapshot::kMaxTotalSteps,
          "snapshot.total_steps", snapshot.total_steps, "an integer in [0, 2^53]");
  for (const ContactSolver::SeedContact& c : snapshot.seed_contacts) {
    require(c.particle >= 0 && c.particle < model_.num_particles(),
            "snapshot.seed_contacts.particle", c.particle, "a particle index of the model");
  }
  if (snapshot.model_values) {
    // The edited values onto a copy, validated as a whole before anything changes.
    ModelValues& values = *snapshot.model_values;
    require(values.ks.size() == model_.springs.ks.size() &&
                values.kd.size() == model_.springs.kd.size(),
            "snapshot.model_values.ks.size", values.ks.size(),
            "the model's spring count (" + std::to_string(model_.springs.size()) + ")");
    require(values.mass.size() == model_.mass.size(), "snapshot.model_values.mass.size",
            values.mass.size(), "the model's particle count");
    Model edited = model_;
    edited.springs.ks = std::move(values.ks);
    edited.springs.kd = std::move(values.kd);
    edited.mass = std::move(values.mass);
    edited.gravity = values.gravity;
    edited.pins = std::move(values.pins);
    edited.validate();
    model_ = std::move(edited);
    model_changed();
  }
  integrator_->restore_internal_state(snapshot.integrator_state);
  assign_state(state_, s);
  contacts_->restore(std::move(snapshot.seed_contacts), snapshot.contact_count);
  total_steps_ = snapshot.total_steps;
  next_output_ = snapshot.next_output;
  frames_ = 0;
}

namespace {
// The steps of this run that missed a tolerance of the integrator (the counts since `before`)
// make it kCompletedWithWarnings, each kind named with its count in the reason.
void warn_of_tolerance_misses(const std::vector<ToleranceMiss>& before,
                              const std::vector<ToleranceMiss>& after, RunReport& report) {
  for (std::size_t i = 0; i < after.size(); ++i) {
    const long earlier = i < before.size() && before[i].what == after[i].what ? before[i].steps : 0;
    const long missed = after[i].steps - earlier;
    if (missed <= 0) continue;
    report.status = RunStatus::kCompletedWithWarnings;
    if (!report.reason.empty()) report.reason += "; ";
    report.reason += after[i].what + " on " + std::to_string(missed) + " of " +
                     std::to_string(report.steps) + " steps";
  }
}
}  // namespace

int Simulator::step_threads() {
  if (options_.threads > 0) return options_.threads;
  if (!team_) team_ = std::make_unique<parallel::TeamChooser>(parallel::available_cores());
  return team_->threads();
}

StepResult Simulator::step() {
  const auto start = std::chrono::steady_clock::now();
  const int threads = step_threads();
  const bool bodies = body_contact_->active(model_);
  const Dynamics dynamics(model_, *contacts_, &terrains_, bands_.get(), &anchors_, threads,
                          bodies ? body_contact_.get() : nullptr, &forces_);
  parallel::copy(threads, state_.x, before_.x);
  parallel::copy(threads, state_.v, before_.v);
  before_.t = state_.t;
  // Collision detection apart from integration: the pairs that may touch in this step, which
  // the integrator's solve or finish_step()'s resolve takes.
  if (bodies) body_contact_->collide(model_, state_, options_.dt);
  StepResult result;
  try {
    result = integrator_->step(dynamics, state_, options_.dt);
  } catch (...) {
    // A force of the user's failed: back to the last completed step.
    parallel::copy(threads, before_.x, state_.x);
    parallel::copy(threads, before_.v, state_.v);
    state_.t = before_.t;
    force_evaluations_ += dynamics.force_evaluations();
    throw;
  }
  force_evaluations_ += dynamics.force_evaluations();
  if (!result.ok) return result;
  finish_step(result, *contacts_, bodies ? body_contact_.get() : nullptr, model_, terrains_,
              before_, state_, options_.dt, threads);
  ++total_steps_;
  if (team_ && options_.threads == 0)
    team_->record(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return result;
}

void Simulator::emit_frame() {
  observers_.for_each([this](Observer& o) { o.on_frame(*this); });
  ++frames_;
  if (options_.output_interval > 0) {
    while (next_output_ <= state_.t + 1e-9 * options_.dt) next_output_ += options_.output_interval;
  }
}

void Simulator::note_forces(RunReport& report) {
  for (const std::shared_ptr<Force>& force : forces_) {
    std::string note;
    if (integrator_->uses_force_jacobians()) {
      if (force->has_jacobian()) continue;
      note = "force '" + force->name() +
             "' gives no Jacobian: " + integrator_->without_force_jacobian();
    } else if (integrator_->is_implicit() && integrator_->is_adaptive()) {
      // ARKODE's DIRK: the force is in every implicit stage's residual, not in its matrix.
      note = "force '" + force->name() + "': " + std::string(integrator_->name()) +
             "'s Newton matrix leaves added forces out with this linear_solver (more Newton "
             "iterations or smaller steps)";
    } else if (integrator_->is_implicit()) {
      note = "force '" + force->name() + "': " + std::string(integrator_->name()) +
             " treats added forces explicitly within each step";
    } else {
      continue;
    }
    if (std::find(noted_.begin(), noted_.end(), note) != noted_.end()) continue;
    noted_.push_back(note);
    report.notes.push_back(std::move(note));
  }
}

RunReport Simulator::run_until(Real t_end) {
  require(std::isfinite(t_end), "t_end", t_end, "a finite time");
  // A step or output interval lost to rounding at the run's largest time (t + h == t) would loop
  // forever. (io/detail/run_limits.hpp checks a whole run's step and frame counts before it
  // starts.)
  const Real largest = std::max(std::abs(state_.t), std::abs(t_end));
  require(state_.t >= t_end - 0.5 * options_.dt || largest + options_.dt > largest, "integrator.dt",
          options_.dt, "a step not lost to rounding at t = " + to_text(largest));
  require(options_.output_interval == 0 || largest + options_.output_interval > largest,
          "output_interval", options_.output_interval,
          "an interval not lost to rounding at t = " + to_text(largest));
  const auto start = std::chrono::steady_clock::now();
  const long evaluations_before = force_evaluations_;
  RunReport report;
  const std::vector<ToleranceMiss> misses_before = integrator_->tolerance_misses();
  if (frames_ == 0) emit_frame();
  const Real dt = options_.dt;
  while (state_.t < t_end - 0.5 * dt) {
    const StepResult result = step();
    if (!result.ok) {
      report.status = RunStatus::kSolverFailed;
      report.reason = result.message;
      break;
    }
    ++report.steps;
    if (auto why = options_.divergence.check(model_, state_, step_threads())) {
      report.status = RunStatus::kDiverged;
      report.reason = *why;
      break;
    }
    if (options_.output_interval == 0 || state_.t >= next_output_ - 1e-9 * dt) emit_frame();
  }
  report.t = state_.t;
  if (report.status == RunStatus::kCompleted)
    warn_of_tolerance_misses(misses_before, integrator_->tolerance_misses(), report);
  report.force_evaluations = force_evaluations_ - evaluations_before;
  note_forces(report);
  report.statistics = integrator_->statistics();
  report_crushed_bodies(model_, state_.x, options_.crush, report);
  if (body_contact_->active(model_)) {
    const BodyContact::Stats& b = body_contact_->stats();
    report.statistics["body_contact_pairs"] = static_cast<double>(b.pairs);
    report.statistics["body_contact_energy_limited"] = static_cast<double>(b.limited);
    report.statistics["body_contact_collided_steps"] = static_cast<double>(b.collided);
    report.statistics["body_contact_searched_steps"] = static_cast<double>(b.searched);
    report.statistics["broad_phase_ms"] = 1e3 * b.broad_seconds;
    report.statistics["narrow_phase_ms"] = 1e3 * b.narrow_seconds;
  }
  report.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  observers_.for_each([this, &report](Observer& o) { o.on_finish(*this, report); });
  return report;
}

}  // namespace jelly
