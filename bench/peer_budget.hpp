#pragma once
// The frame budget side by side with another engine (issue 39): two scenes, the 64 x 64 cloth
// falling over a sphere (scenes/cloth_on_sphere.json with nu = nv = 64) and the n = 20 seed cube
// dropped on the coulomb slope (scenes/seed_slope.json with cube.n = 20, coulomb contact), each
// run frame by frame (1/60 s) by every setup in turn, round after round (alternation: a busy
// machine slows them alike). Per scene and setup: the wall time of a frame, the deepest
// penetration into a terrain, the largest spring stretch and the cube's volume ratio
// (docs/performance.md).
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include <jelly/bench/table.hpp>
#include <jelly/io/scene.hpp>
#include <jelly/solvers/integrators/integrator_options.hpp>

namespace jelly::bench {

// What a frame is judged by, from the particles' positions at its end.
struct FrameMeasures {
  Real penetration = 0;     // deepest signed distance below any terrain's surface (m), >= 0
  Real stretch = 0;         // largest (L - l0) / l0 over the springs
  Real volume_ratio = NAN;  // lattice cube: deformed / rest volume of its cells; else NAN
  int inverted_cells = 0;   // lattice cube: cells of negative volume
};
// `lattice_n` > 0: the model is one n^3 lattice cube (geometry/cube.hpp's numbering).
FrameMeasures measure_frame(const Model& model, const Terrains& terrains, const VecX& x, Real t,
                            int lattice_n);

// "cloth64" or "cube20" from the scene files in `scenes_dir`; throws InputError for another name.
Scene peer_scene(const std::string& name, const std::string& scenes_dir);
// The scene's lattice size for measure_frame (20 for "cube20", 0 otherwise).
int peer_lattice_n(const std::string& name);

// One engine's run of a scene from its start, a frame per call.
class PeerRun {
 public:
  virtual ~PeerRun() = default;
  // Advances one frame; false when the engine failed (why() says how).
  virtual bool frame() = 0;
  // The particles' positions now, in the model's order (3N).
  virtual const VecX& positions() = 0;
  virtual std::string why() const { return {}; }
};

struct PeerSetup {
  std::string label;   // "vbd i10", "bullet"
  std::string engine;  // "jelly" or the peer's name
  std::function<std::unique_ptr<PeerRun>(const Scene&, Real frame)> make;
};

// jelly with `integrator` and its options, `steps_per_frame` steps of frame / steps_per_frame
// per frame, on `threads` threads (0 = all).
PeerSetup jelly_peer_setup(const std::string& label, const std::string& integrator,
                           const IntegratorOptions& options, int threads, int steps_per_frame = 1);
// vbd, xpbd and implicit_euler with the given options (labels "vbd i<iterations>",
// "xpbd s<substeps>", "implicit_euler"), one step per frame each.
std::vector<PeerSetup> default_jelly_peer_setups(int threads, const IntegratorOptions& options);

struct PeerBudgetOptions {
  std::vector<std::string> scenes{"cloth64", "cube20"};
  std::string scenes_dir;  // the folder of cloth_on_sphere.json and seed_slope.json
  Real frame = 1.0 / 60;   // s
  Real duration = 3;       // s simulated per run
  int rounds = 3;          // runs of every setup, in alternation
  std::string reference;   // label the time ratios are taken against (empty: none)
  // Label of the setup whose stretch is the material's (a converged solution: rk4 at a small
  // step): the others' stretch is also given beyond it (empty: none).
  std::string converged;
  std::ostream* progress = nullptr;
  void validate() const;
};

// Rows per scene and setup: frame time (median, mean, max over every frame of every round),
// time_ratio (median over rounds of the setup's mean frame time over the reference's in the
// same round), the worst measures over the runs' frames, and the largest and last stretch less
// the converged setup's.
Table run_peer_budget(const PeerBudgetOptions& options, const std::vector<PeerSetup>& setups);

}  // namespace jelly::bench
