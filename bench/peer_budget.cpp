#include <jelly/bench/peer_budget.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

#include <jelly/core/errors.hpp>
#include <jelly/core/measures.hpp>
#include <jelly/geometry/cube.hpp>

namespace jelly::bench {

namespace {

Real median_of(std::vector<Real> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

class JellyRun final : public PeerRun {
 public:
  JellyRun(Simulator sim, int steps_per_frame)
      : sim_(std::move(sim)), steps_per_frame_(steps_per_frame) {}
  bool frame() override {
    for (int k = 0; k < steps_per_frame_; ++k) {
      const StepResult r = sim_.step();
      if (!r.ok) {
        why_ = r.message;
        return false;
      }
    }
    if (auto why = sim_.options().divergence.check(sim_.model(), sim_.state())) {
      why_ = *why;
      return false;
    }
    return true;
  }
  const VecX& positions() override { return sim_.state().x; }
  std::string why() const override { return why_; }

 private:
  Simulator sim_;
  int steps_per_frame_;
  std::string why_;
};

}  // namespace

FrameMeasures measure_frame(const Model& model, const Terrains& terrains, const VecX& x, Real t,
                            int lattice_n) {
  FrameMeasures m;
  for (const auto& terrain : terrains)
    for (int i = 0; i < model.num_particles(); ++i)
      m.penetration = std::max(m.penetration, -terrain->signed_distance(particle(x, i), t));
  const Springs& s = model.springs;
  for (int k = 0; k < s.size(); ++k) {
    const Real length = (Vec3(particle(x, s.a[k])) - Vec3(particle(x, s.b[k]))).norm();
    m.stretch = std::max(m.stretch, (length - s.rest_length[k]) / s.rest_length[k]);
  }
  if (lattice_n > 1) {
    const BodyVolume v = body_volume(model, model.bodies[0], x);
    m.volume_ratio = v.ratio();
    m.inverted_cells = static_cast<int>(v.inverted);
  }
  return m;
}

Scene peer_scene(const std::string& name, const std::string& scenes_dir) {
  if (name == "cloth64")
    return load_scene(scenes_dir + "/cloth_on_sphere.json", {"bodies.0.nu=64", "bodies.0.nv=64"});
  if (name == "cube20")
    return load_scene(scenes_dir + "/seed_slope.json",
                      {"cube.n=20", "terrains.0.contact.model=\"coulomb\""});
  throw InputError("--scenes", name, "\"cloth64\" or \"cube20\"");
}

int peer_lattice_n(const std::string& name) { return name == "cube20" ? 20 : 0; }

PeerSetup jelly_peer_setup(const std::string& label, const std::string& integrator,
                           const IntegratorOptions& options, int threads, int steps_per_frame) {
  PeerSetup s;
  s.label = label;
  s.engine = "jelly";
  s.make = [integrator, options, threads, steps_per_frame](const Scene& scene, Real frame) {
    Scene copy = scene;
    copy.integrator.name = integrator;
    copy.integrator.options = options;
    copy.integrator.dt = frame / steps_per_frame;
    copy.threads = threads;
    return std::unique_ptr<PeerRun>(new JellyRun(make_simulator(copy), steps_per_frame));
  };
  return s;
}

std::vector<PeerSetup> default_jelly_peer_setups(int threads, const IntegratorOptions& options) {
  std::vector<PeerSetup> s;
  s.push_back(
      jelly_peer_setup("vbd i" + std::to_string(options.vbd.iterations), "vbd", options, threads));
  s.push_back(
      jelly_peer_setup("xpbd s" + std::to_string(options.xpbd.substeps), "xpbd", options, threads));
  s.push_back(jelly_peer_setup("implicit_euler", "implicit_euler", options, threads));
  return s;
}

void PeerBudgetOptions::validate() const {
  require(!scenes.empty(), "--scenes", "(empty)", "\"cloth64\" and/or \"cube20\"");
  for (const std::string& s : scenes)
    require(s == "cloth64" || s == "cube20", "--scenes", s, "\"cloth64\" or \"cube20\"");
  require(std::isfinite(frame) && frame > 0, "--frame", frame, "a frame time > 0 s");
  require(std::isfinite(duration) && duration >= frame, "--duration", duration,
          "a time >= one frame");
  require(rounds >= 1 && rounds <= 1000, "--rounds", rounds, "an integer in [1, 1000]");
}

Table run_peer_budget(const PeerBudgetOptions& o, const std::vector<PeerSetup>& setups) {
  o.validate();
  using Clock = std::chrono::steady_clock;
  Table table("peer_budget",
              "frame by frame (one step per frame) in alternation, rounds x setups: frame_ms = "
              "wall time of one frame (median/mean/max over all frames of all rounds), "
              "time_ratio = median over rounds of mean frame time / the reference's; "
              "penetration_max (m), stretch_max ((L - l0) / l0 over all springs and frames), "
              "stretch_end (last frame), volume_ratio_min/_end and inverted_cells_max/_end "
              "(cube: worst frame, last frame), stretch_beyond_max/_end (stretch_max/_end less "
              "the converged setup's)",
              {"scene:s",
               "setup:s",
               "engine:s",
               "particles",
               "springs",
               "status:s",
               "frames",
               "frame_ms_median",
               "frame_ms_mean",
               "frame_ms_max",
               "time_ratio",
               "penetration_max",
               "stretch_max",
               "stretch_end",
               "volume_ratio_min",
               "volume_ratio_end",
               "inverted_cells_max",
               "inverted_cells_end",
               "stretch_beyond_max",
               "stretch_beyond_end",
               "reason:s"});
  const int frames = static_cast<int>(std::lround(o.duration / o.frame));
  for (const std::string& name : o.scenes) {
    const Scene scene = peer_scene(name, o.scenes_dir);
    const Simulator probe = make_simulator(scene);
    const Model& model = probe.model();
    const Terrains& terrains = probe.terrains();
    const int lattice = peer_lattice_n(name);
    struct Result {
      std::vector<Real> times, round_means;
      FrameMeasures worst;
      Real stretch_end = NAN, volume_end = NAN;
      int inverted_end = 0;
      int done = 0;
      std::string status = "completed", reason;
    };
    std::vector<Result> results(setups.size());
    for (Result& r : results) r.worst.volume_ratio = lattice ? INFINITY : NAN;
    for (int round = 0; round < o.rounds; ++round) {
      for (size_t k = 0; k < setups.size(); ++k) {
        Result& r = results[k];
        if (r.status != "completed") continue;
        std::unique_ptr<PeerRun> run = setups[k].make(scene, o.frame);
        Real sum = 0;
        int f = 0;
        for (; f < frames; ++f) {
          const auto start = Clock::now();
          const bool ok = run->frame();
          const Real seconds = std::chrono::duration<double>(Clock::now() - start).count();
          if (!ok || !run->positions().allFinite()) {
            r.status = "failed";
            r.reason = run->why().empty() ? "a position is not finite" : run->why();
            break;
          }
          r.times.push_back(seconds);
          sum += seconds;
          const FrameMeasures m =
              measure_frame(model, terrains, run->positions(), (f + 1) * o.frame, lattice);
          r.worst.penetration = std::max(r.worst.penetration, m.penetration);
          r.worst.stretch = std::max(r.worst.stretch, m.stretch);
          r.worst.inverted_cells = std::max(r.worst.inverted_cells, m.inverted_cells);
          if (lattice) r.worst.volume_ratio = std::min(r.worst.volume_ratio, m.volume_ratio);
          r.stretch_end = m.stretch;
          r.volume_end = m.volume_ratio;
          r.inverted_end = m.inverted_cells;
        }
        r.done = f;
        r.round_means.push_back(f > 0 ? sum / f : NAN);
        if (o.progress) {
          *o.progress << "peer budget " << name << " round " << round + 1 << " " << setups[k].label
                      << ": " << (f > 0 ? 1e3 * sum / f : NAN) << " ms/frame, " << r.status
                      << std::endl;
        }
      }
    }
    int reference = -1, converged = -1;
    for (size_t k = 0; k < setups.size(); ++k) {
      if (setups[k].label == o.reference) reference = static_cast<int>(k);
      if (setups[k].label == o.converged && results[k].status == "completed")
        converged = static_cast<int>(k);
    }
    for (size_t k = 0; k < setups.size(); ++k) {
      const Result& r = results[k];
      Real ratio = NAN;
      if (reference >= 0) {
        std::vector<Real> ratios;
        const auto& ref = results[reference].round_means;
        for (size_t q = 0; q < std::min(ref.size(), r.round_means.size()); ++q)
          ratios.push_back(r.round_means[q] / ref[q]);
        ratio = median_of(ratios);
      }
      Real mean = 0, worst = 0;
      for (Real t : r.times) {
        mean += t / r.times.size();
        worst = std::max(worst, t);
      }
      table.add_row({name,
                     setups[k].label,
                     setups[k].engine,
                     static_cast<double>(model.num_particles()),
                     static_cast<double>(model.springs.size()),
                     r.status,
                     static_cast<double>(r.done),
                     1e3 * median_of(r.times),
                     1e3 * mean,
                     1e3 * worst,
                     ratio,
                     r.worst.penetration,
                     r.worst.stretch,
                     r.stretch_end,
                     lattice ? r.worst.volume_ratio : NAN,
                     lattice ? r.volume_end : NAN,
                     lattice ? static_cast<double>(r.worst.inverted_cells) : NAN,
                     lattice ? static_cast<double>(r.inverted_end) : NAN,
                     converged >= 0 ? r.worst.stretch - results[converged].worst.stretch : NAN,
                     converged >= 0 ? r.stretch_end - results[converged].stretch_end : NAN,
                     r.reason});
    }
  }
  return table;
}

}  // namespace jelly::bench
