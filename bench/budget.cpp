#include <jelly/bench/budget.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>

#include <jelly/bench/accuracy.hpp>
#include <jelly/bench/memory.hpp>
#include <jelly/bench/scenes.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/solvers/integrators/registry.hpp>

namespace jelly::bench {

std::vector<BudgetSetup> default_budget_setups() {
  std::vector<BudgetSetup> s;
  s.push_back({"symplectic_euler", "symplectic_euler", {}, 0});
  s.push_back({"rk4", "rk4", {}, 0});
  s.push_back({"implicit_euler", "implicit_euler", {}, 1});
  for (int iterations : {5, 10, 20}) {
    IntegratorOptions o;
    o.pd.iterations = iterations;
    s.push_back({"pd i" + std::to_string(iterations), "projective_dynamics", o, 1});
  }
  IntegratorOptions cheb;
  cheb.pd.iterations = 10;
  cheb.pd.chebyshev = true;
  s.push_back({"pd i10 cheb", "projective_dynamics", cheb, 1});
  for (int substeps : {1, 5, 20}) {
    IntegratorOptions o;
    o.xpbd.substeps = substeps;
    s.push_back({"xpbd s" + std::to_string(substeps), "xpbd", o, 1});
  }
  // vbd's penalty contact inside its sweeps (contact after the step only crushes the cube).
  IntegratorOptions vbd;
  vbd.vbd.iterations = 10;
  vbd.vbd.contact_hardness = 100;
  s.push_back({"vbd i10 h100", "vbd", vbd, 1});
  return s;
}

void BudgetOptions::validate() const {
  require(!sizes.empty() || !cloth_sizes.empty(), "--sizes", "(empty)",
          "at least one cube size (or a --cloth size)");
  for (int n : sizes) require(n >= 2 && n <= 100, "--sizes", n, "sizes in [2, 100]");
  for (int n : cloth_sizes) require(n >= 2 && n <= 512, "--cloth", n, "sizes in [2, 512]");
  require(cloth_sizes.empty() || !scenes_dir.empty(), "--scenes-dir", "(empty)",
          "the folder of cloth_on_sphere.json");
  require(std::isfinite(frame) && frame > 0, "--frame", frame, "a frame time > 0 s");
  require(std::isfinite(horizon) && horizon >= frame, "--horizon", horizon, "a time >= one frame");
  require(std::isfinite(search_horizon) && search_horizon >= frame, "--search-horizon",
          search_horizon, "a time >= one frame");
  require(std::isfinite(ks) && ks > 0, "--ks", ks, "a stiffness > 0");
  require(std::isfinite(kd) && kd >= 0, "--kd", kd, "a damping >= 0");
  require(reference_steps_per_frame >= 1, "--reference-steps", reference_steps_per_frame,
          "an integer >= 1");
  require(sample_every >= 1, "sample_every", sample_every, "an integer >= 1");
  for (int k : steps_ladder) require(k >= 1, "steps_ladder", k, "integers >= 1");
  for (Real k : ks_ladder) require(k > 0, "--ks-ladder", k, "stiffnesses > 0");
}

namespace {

using Clock = std::chrono::steady_clock;

// What one row measures: the seed cube of n per edge, or the cloth of n x n particles.
struct BudgetScene {
  bool cloth = false;
  int n = 0;
  bool operator<(const BudgetScene& other) const {
    return cloth != other.cloth ? other.cloth : n < other.n;
  }
};

// The cloth of scenes/cloth_on_sphere.json with nu = nv = n, at rest, over its sphere and floor.
SceneParts budget_cloth(const BudgetOptions& o, int n) {
  const Scene scene =
      load_scene(o.scenes_dir + "/cloth_on_sphere.json",
                 {"bodies.0.nu=" + std::to_string(n), "bodies.0.nv=" + std::to_string(n)});
  SceneParts parts;
  parts.model = make_model(scene);
  parts.state = initial_state(parts.model);
  for (const auto& spec : scene.terrains) parts.terrains.push_back(make_terrain(*spec));
  return parts;
}

// The cube at (ks, kd); the cloth keeps its scene's springs (its rows search no ks ladder).
SceneParts budget_scene(const BudgetOptions& o, const BudgetScene& what, Real ks, Real kd) {
  if (what.cloth) return budget_cloth(o, what.n);
  const int n = what.n;
  SceneSpec spec;
  spec.name = "slope";
  spec.n = n;
  spec.ks = ks;
  spec.kd = kd;
  SceneParts parts = build_scene(spec);
  if (o.lowered) {  // the lowest particle 0.1 m above the slope
    const Terrain& slope = *parts.terrains.front();
    Real lowest = INFINITY;
    for (int i = 0; i < parts.model.num_particles(); ++i)
      lowest = std::min(lowest, slope.signed_distance(particle(parts.state.x, i), 0));
    const Vec3 normal = slope.normal(Vec3::Zero(), 0);
    for (int i = 0; i < parts.model.num_particles(); ++i)
      particle(parts.state.x, i) -= (lowest - 0.1) * normal;
  }
  return parts;
}

// A simulator of the scene at steps_per_frame steps per frame, guarded by the stability
// command's energy cap over `horizon`.
Simulator budget_simulator(SceneParts parts, const std::string& integrator,
                           const IntegratorOptions& options, Real dt, Real horizon) {
  SimulatorOptions so;
  so.dt = dt;
  so.output_interval = horizon + 1;
  so.divergence.max_energy = energy_cap(parts, horizon, 1.0);
  Simulator sim(std::move(parts.model), std::move(parts.state),
                make_integrator(integrator, options), so);
  for (auto& t : parts.terrains) sim.add_terrain(std::move(t));
  return sim;
}

bool stable(const BudgetOptions& o, const BudgetScene& n, const BudgetSetup& setup, int steps,
            Real ks) {
  const Real kd = ks * (o.kd / o.ks);
  Simulator sim = budget_simulator(budget_scene(o, n, ks, kd), setup.integrator, setup.options,
                                   o.frame / steps, o.search_horizon);
  return sim.run_until(o.search_horizon).ok();
}

struct BudgetReference {
  std::vector<Vec3> com;        // per frame (frame 0 = initial)
  std::vector<Real> energy;     // per frame
  std::vector<VecX> positions;  // every sample_every frames
};

BudgetReference make_budget_reference(const BudgetOptions& o, const BudgetScene& n, int frames) {
  SceneParts parts = budget_scene(o, n, o.ks, o.kd);
  const Model model = parts.model;
  Simulator sim = budget_simulator(std::move(parts), "rk4", {},
                                   o.frame / o.reference_steps_per_frame, o.horizon);
  BudgetReference r;
  for (int f = 0; f <= frames; ++f) {
    if (f > 0) {
      const RunReport report = sim.run_until(f * o.frame);
      if (!report.ok())
        throw std::runtime_error("budget: the RK4 reference diverged: " + report.brief());
    }
    r.com.push_back(center_of_mass(model, sim.state()));
    r.energy.push_back(total_energy(model, sim.state()));
    if (f % o.sample_every == 0) r.positions.push_back(sim.state().x);
  }
  return r;
}

Real median(std::vector<Real> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

}  // namespace

Table run_budget(const BudgetOptions& o) {
  o.validate();
  std::vector<BudgetSetup> setups = o.setups.empty() ? default_budget_setups() : o.setups;
  if (!o.labels.empty()) {
    const std::set<std::string> wanted(o.labels.begin(), o.labels.end());
    for (const std::string& label : wanted) {
      const bool known = std::any_of(setups.begin(), setups.end(),
                                     [&](const BudgetSetup& s) { return s.label == label; });
      std::string all;
      for (const BudgetSetup& s : setups) all += (all.empty() ? "" : ", ") + s.label;
      require(known, "--setups", label, "labels among: " + all);
    }
    setups.erase(std::remove_if(setups.begin(), setups.end(),
                                [&](const BudgetSetup& s) { return !wanted.count(s.label); }),
                 setups.end());
  }
  for (const BudgetSetup& s : setups) make_integrator(s.integrator, s.options);
  // A cloth scene that cannot be read fails now, not after the cubes' minutes of measuring.
  for (int n : o.cloth_sizes) budget_cloth(o, n);
  Table table(
      "budget",
      "seed cube on the seed slope (coulomb contact), or the cloth over its sphere (scene "
      "cloth: n x n particles), frame by frame: frame_seconds = median wall "
      "time of one frame's steps; errors against RK4 at frame / reference_steps (error_max: "
      "largest RMS particle distance over samples, com_error_max: largest centre-of-mass "
      "distance over frames); energies relative to |E0|; fewest_stable_steps: fewest steps per "
      "frame (of the ladder) stable at the seed material; stiffest_ks: largest ks of the ladder "
      "(kd proportional) stable at steps_per_frame",
      {"item",
       "scene:s",
       "n",
       "particles",
       "springs",
       "setup:s",
       "integrator:s",
       "steps_per_frame",
       "status:s",
       "frames",
       "frame_seconds",
       "frame_seconds_mean",
       "frame_seconds_max",
       "error_max",
       "error_end",
       "com_error_max",
       "energy_end_vs_reference",
       "energy_growth_max",
       "fewest_stable_steps",
       "stiffest_ks",
       "peak_memory_bytes",
       "reason:s"});
  const int frames = static_cast<int>(std::lround(o.horizon / o.frame));
  std::map<BudgetScene, BudgetReference> references;
  std::vector<BudgetScene> scenes;
  for (int n : o.sizes) scenes.push_back({false, n});
  for (int n : o.cloth_sizes) scenes.push_back({true, n});
  long item = 0;
  for (const BudgetScene& n : scenes) {
    for (const BudgetSetup& setup : setups) {
      const long this_item = item++;
      if (!o.shard.owns(this_item)) continue;
      if (!references.count(n)) references[n] = make_budget_reference(o, n, frames);
      const BudgetReference& ref = references[n];
      // Steps per frame: given, or the fewest of the ladder stable at the seed material.
      int steps = setup.steps_per_frame;
      Real fewest = NAN;
      if (steps == 0) {
        for (int k : o.steps_ladder) {
          if (stable(o, n, setup, k, o.ks)) {
            steps = k;
            fewest = k;
            break;
          }
        }
      }
      std::vector<Cell> row{static_cast<double>(this_item), std::string(n.cloth ? "cloth" : "cube"),
                            static_cast<double>(n.n)};
      SceneParts parts = budget_scene(o, n, o.ks, o.kd);
      const Model model = parts.model;
      row.insert(row.end(), {static_cast<double>(model.num_particles()),
                             static_cast<double>(model.springs.size()), setup.label,
                             setup.integrator, steps > 0 ? static_cast<double>(steps) : NAN});
      if (steps == 0) {
        row.insert(row.end(), {std::string("unstable_at_max_steps"), 0.0, NAN, NAN, NAN, NAN, NAN,
                               NAN, NAN, NAN, NAN, NAN, NAN,
                               std::string("no steps per frame of the ladder was stable")});
        table.add_row(row);
        continue;
      }
      // The measured run.
      reset_peak_memory();
      Simulator sim = budget_simulator(std::move(parts), setup.integrator, setup.options,
                                       o.frame / steps, o.horizon);
      const Real scale = std::abs(ref.energy.front());
      std::vector<Real> times;
      Real error_max = 0, error_end = NAN, com_error = 0, growth = -INFINITY;
      Real previous = total_energy(model, sim.state());
      std::string status = "completed", reason;
      int done = 0;
      for (int f = 1; f <= frames && status == "completed"; ++f) {
        const auto start = Clock::now();
        for (int k = 0; k < steps; ++k) {
          const StepResult r = sim.step();
          if (!r.ok) {
            status = "solver_failed";
            reason = r.message;
            break;
          }
        }
        times.push_back(std::chrono::duration<double>(Clock::now() - start).count());
        if (status != "completed") break;
        if (auto why = sim.options().divergence.check(model, sim.state())) {
          status = "diverged";
          reason = *why + " at t = " + to_text(sim.state().t);
          break;
        }
        done = f;
        const Real e = total_energy(model, sim.state());
        growth = std::max(growth, (e - previous) / scale);
        previous = e;
        com_error = std::max(com_error, (center_of_mass(model, sim.state()) - ref.com[f]).norm());
        if (f % o.sample_every == 0) {
          error_end = rms_position_error(sim.state().x, ref.positions[f / o.sample_every]);
          error_max = std::max(error_max, error_end);
        }
      }
      const double peak = peak_memory_bytes();
      const bool ok = status == "completed";
      if (ok && setup.steps_per_frame == 1) fewest = 1;
      const Real energy_end = ok ? (previous - ref.energy[frames]) / scale : NAN;
      Real mean = 0, worst = 0;
      for (Real t : times) {
        mean += t / times.size();
        worst = std::max(worst, t);
      }
      // The stiffest ks of the ladder that stays stable at these steps per frame.
      Real stiffest = NAN;
      if (ok && !n.cloth && n.n <= o.ks_search_max_n) {
        for (Real ks : o.ks_ladder) {
          if (!stable(o, n, setup, steps, ks)) break;
          stiffest = ks;
        }
      }
      row.insert(row.end(), {status, static_cast<double>(done), median(times), mean, worst,
                             ok ? error_max : NAN, ok ? error_end : NAN, ok ? com_error : NAN,
                             energy_end, ok ? growth : NAN, fewest, stiffest, peak, reason});
      table.add_row(row);
      if (o.progress) {
        *o.progress << "budget item " << this_item << ": " << (n.cloth ? "cloth" : "cube") << " n "
                    << n.n << " " << setup.label << ", " << steps << " steps/frame: " << status
                    << ", " << median(times) * 1e3 << " ms/frame" << std::endl;
      }
    }
  }
  return table;
}

}  // namespace jelly::bench
