#include <jelly/solvers/contact/body_contact.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/core/json.hpp>
#include <jelly/solvers/contact/detail/body_contact_fields.hpp>

namespace jelly {

namespace {

void check_body_friction(const BodyContactParams& p, const std::string& prefix) {
  require(p.static_friction >= p.friction, prefix + "static_friction", p.static_friction,
          "a finite number >= friction (" + to_text(p.friction) + ")");
}

// static_friction not given: at least friction.
void body_static_friction_default(JsonFields& f, BodyContactParams& p) {
  if (!json_field_has(f, "static_friction"))
    p.static_friction = std::max(p.static_friction, p.friction);
}

}  // namespace

const FieldTable<BodyContactParams>& body_contact_fields() {
  using P = BodyContactParams;
  static const FieldTable<P> table{
      "BodyContactParams",
      "body_contact",
      "Contact between bodies (docs/contact.md); each body's particles are spheres of its "
      "radius",
      {
          boolean_field<&P::enabled>("enabled", "Contact between different bodies"),
          boolean_field<&P::self_contact>("self_contact",
                                          "Contact between parts of one body that no spring joins"),
          number_field<&P::restitution>("restitution", "", range_closed(0, 1), "a number in [0, 1]",
                                        "Normal velocity kept, reversed, by a bounce"),
          number_field<&P::friction>("friction", "", range_at_least(0), "a finite number >= 0",
                                     "Kinetic friction coefficient"),
          number_field<&P::static_friction>(
              "static_friction", "", range_finite(), "a finite number >= friction",
              "Static friction coefficient, >= friction (default: at least friction)"),
          number_field<&P::resting_speed>("resting_speed", "m/s", range_at_least(0),
                                          "a finite speed >= 0",
                                          "A slower approach is absorbed, never reflected"),
          integer_field<&P::iterations>("iterations", "", range_closed(1, 100),
                                        "an integer in [1, 100]",
                                        "Passes over the contact pairs per step"),
      },
      &check_body_friction,
      &body_static_friction_default,
  };
  return table;
}

void BodyContactParams::validate(const std::string& prefix) const {
  validate_fields(body_contact_fields(), *this, prefix);
}

BodyContactParams BodyContactParams::read(JsonFields& f) {
  BodyContactParams p;
  read_fields(body_contact_fields(), f, p, f.prefix(), /*reject_unknown=*/true);
  return p;
}

Json BodyContactParams::to_json() const {
  Json j = Json::object();
  write_fields(body_contact_fields(), *this, j);
  return j;
}

BodyContact::BodyContact(BodyContactParams params) : params_(params) {
  params_.validate("body_contact.");
}

bool BodyContact::active(const Model& model) const {
  return (params_.enabled && model.num_bodies() >= 2) ||
         (params_.self_contact && model.num_bodies() >= 1);
}

void BodyContact::prepare(const Model& model) {
  const int n = model.num_particles();
  if (prepared_for_ == &model && prepared_particles_ == n &&
      prepared_springs_ == model.springs.size())
    return;
  prepared_for_ = &model;
  prepared_particles_ = n;
  prepared_springs_ = model.springs.size();
  radius_.resize(n);
  inverse_mass_ = model.mass.cwiseInverse();
  body_.assign(n, -1);
  for (int b = 0; b < model.num_bodies(); ++b) {
    const Body& body = model.bodies[b];
    const Real r = body.radius > 0 ? body.radius : 0.5 * body.spacing;
    for (int i = body.first_particle; i < body.end_particle(); ++i) {
      body_[i] = b;
      radius_[i] = r;
    }
  }
  for (int i = 0; i < n; ++i) {
    if (!(radius_[i] > 0)) radius_[i] = 0;  // a particle outside every body takes no part
  }
  for (int k = 0; k < model.pins.size(); ++k) inverse_mass_[model.pins.particles[k]] = 0;
  // The springs' neighbours of each particle (CSR, sorted).
  neighbour_start_.assign(n + 1, 0);
  const Springs& s = model.springs;
  for (int k = 0; k < s.size(); ++k) {
    ++neighbour_start_[s.a[k] + 1];
    ++neighbour_start_[s.b[k] + 1];
  }
  for (int i = 0; i < n; ++i) neighbour_start_[i + 1] += neighbour_start_[i];
  neighbours_.resize(neighbour_start_[n]);
  std::vector<int> fill(neighbour_start_.begin(), neighbour_start_.end() - 1);
  for (int k = 0; k < s.size(); ++k) {
    neighbours_[fill[s.a[k]]++] = s.b[k];
    neighbours_[fill[s.b[k]]++] = s.a[k];
  }
  for (int i = 0; i < n; ++i)
    std::sort(neighbours_.begin() + neighbour_start_[i],
              neighbours_.begin() + neighbour_start_[i + 1]);
}

bool BodyContact::joined(int i, int j) const {
  const auto begin = neighbours_.begin() + neighbour_start_[i];
  const auto end = neighbours_.begin() + neighbour_start_[i + 1];
  return std::binary_search(begin, end, j);
}

void BodyContact::filter(const Model& /*model*/) {
  contacts_.clear();
  for (const BroadPhase::Pair& p : candidates_) {
    const int bi = body_[p.first], bj = body_[p.second];
    if (bi < 0 || bj < 0 || radius_[p.first] <= 0 || radius_[p.second] <= 0) continue;
    if (bi != bj ? !params_.enabled : (!params_.self_contact || joined(p.first, p.second)))
      continue;
    if (inverse_mass_[p.first] + inverse_mass_[p.second] <= 0) continue;  // two pins
    contacts_.push_back(p);
  }
}

void BodyContact::check_no_overlap(const Model& model, const VecX& x, Real tolerance) {
  if (!active(model)) return;
  prepare(model);
  broad_.find_pairs(x, radius_, candidates_);
  filter(model);
  for (const BroadPhase::Pair& p : contacts_) {
    const Real reach = radius_[p.first] + radius_[p.second];
    const Real distance = (particle(x, p.second) - particle(x, p.first)).norm();
    if (distance >= reach * (1 - tolerance)) continue;
    const Body& a = model.bodies[body_[p.first]];
    const Body& b = model.bodies[body_[p.second]];
    const std::string what =
        "particle " + std::to_string(p.first - a.first_particle) + " of body \"" + a.name +
        "\" and particle " + std::to_string(p.second - b.first_particle) + " of body \"" + b.name +
        "\" are " + to_text(distance) + " m apart, closer than their contact radii " +
        to_text(radius_[p.first]) + " + " + to_text(radius_[p.second]) + " m";
    if (body_[p.first] != body_[p.second]) {
      throw InputError("bodies \"" + a.name + "\" and \"" + b.name + "\" overlap at the start: " +
                       what + "; move them apart (or make their radius smaller)");
    }
    throw InputError("body \"" + a.name + "\" touches itself at the start (self_contact): " + what +
                     "; turn body_contact.self_contact off or make its radius smaller");
  }
}

const std::vector<BroadPhase::Pair>& BodyContact::find_candidates(const Model& model, const VecX& x,
                                                                  const VecX& pad, Real margin) {
  const auto t0 = std::chrono::steady_clock::now();
  prepare(model);
  padded_ = (1 + margin) * radius_ + pad;
  for (int i = 0; i < padded_.size(); ++i) {
    if (!(radius_[i] > 0)) padded_[i] = 0;
  }
  broad_.find_pairs(x, padded_, candidates_);
  filter(model);
  stats_.broad_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return contacts_;
}

void BodyContact::record_step(const std::vector<BroadPhase::Pair>& pairs, double narrow_seconds) {
  contacts_ = pairs;
  stats_.pairs += static_cast<long>(pairs.size());
  stats_.narrow_seconds += narrow_seconds;
  ++stats_.steps;
}

void BodyContact::resolve(const Model& model, const State& before, State& state, Real h) {
  contacts_.clear();
  if (!active(model)) return;
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  prepare(model);
  broad_.find_pairs(state.x, radius_, candidates_);
  const auto t1 = Clock::now();
  filter(model);
  const BodyContactParams& c = params_;
  // Sequential impulses: every pass resolves each pair with the current positions and velocities.
  for (int pass = 0; pass < c.iterations; ++pass) {
    bool any = false;
    for (const BroadPhase::Pair& p : contacts_) {
      const int i = p.first, j = p.second;
      auto xi = particle(state.x, i);
      auto xj = particle(state.x, j);
      auto vi = particle(state.v, i);
      auto vj = particle(state.v, j);
      const Vec3 d = xj - xi;
      const Real dist = d.norm();
      const Real overlap = radius_[i] + radius_[j] - dist;
      if (overlap <= 0 || dist <= 0) continue;
      any = true;
      const Vec3 n = d / dist;
      const Real wi = inverse_mass_[i], wj = inverse_mass_[j], w = wi + wj;
      // Normal: absorb the approach, or reflect it if it was already there at the step's start.
      const Vec3 rel = vj - vi;
      const Real vn = rel.dot(n);
      if (vn < 0) {
        const Real approach_before = -(particle(before.v, j) - particle(before.v, i)).dot(n);
        const Real vn_new = approach_before > c.resting_speed ? -c.restitution * vn : 0.0;
        const Real dvn = vn_new - vn;  // > 0
        // Coulomb friction on the tangential relative velocity, bounded by mu dv_n.
        const Vec3 vt = rel - vn * n;
        const Real speed_t = vt.norm();
        const bool stick = speed_t <= c.static_friction * dvn;
        const Vec3 dvt = stick ? Vec3(-vt) : Vec3(-(c.friction * dvn / speed_t) * vt);
        // Relative velocity change dv = dvn n + dvt from the impulse P on j (-P on i).
        const Vec3 impulse = (dvn * n + dvt) / w;
        vi -= wi * impulse;
        vj += wj * impulse;
        // Friction acts during the step: the tangential displacement it removes is taken back
        // too (as for a terrain): a sticking pair keeps its relative tangential position of the
        // step's start, a sliding one loses h dv_t. (After a sticking, absorbed contact the pair
        // moves together, so this changes no angular momentum.)
        Vec3 back;
        if (stick) {
          const Vec3 slip = d - (particle(before.x, j) - particle(before.x, i));
          back = -(slip - slip.dot(n) * n);
        } else {
          back = h * dvt;
        }
        xi -= (wi / w) * back;
        xj += (wj / w) * back;
      }
      // Projection along the line of centres (as they are now); the lever it adds to the pair
      // would change the angular momentum by a n x (v_j - v_i): a tangential impulse takes it
      // back exactly.
      const Vec3 d1 = xj - xi;
      const Real dist1 = d1.norm();
      const Real overlap1 = radius_[i] + radius_[j] - dist1;
      if (overlap1 <= 0 || dist1 <= 0) continue;
      const Vec3 n1 = d1 / dist1;
      const Real a = overlap1 / w;
      xi -= (a * wi) * n1;
      xj += (a * wj) * n1;
      const Vec3 rel_after = vj - vi;
      const Vec3 tangential = rel_after - rel_after.dot(n1) * n1;
      const Vec3 q = (-a / (dist1 + overlap1)) * tangential;
      vi -= wi * q;
      vj += wj * q;
    }
    if (!any) break;
  }
  const auto t2 = Clock::now();
  stats_.pairs += static_cast<long>(contacts_.size());
  stats_.broad_seconds += std::chrono::duration<double>(t1 - t0).count();
  stats_.narrow_seconds += std::chrono::duration<double>(t2 - t1).count();
  ++stats_.steps;
}

}  // namespace jelly
