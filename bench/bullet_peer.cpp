// jelly-bench-bullet: the frame budget of docs/performance.md side by side with Bullet's classic
// position-based soft body (btSoftBody in a btSoftRigidDynamicsWorld, 10 position iterations),
// built from the same particles, masses and springs as jelly's scene. Built only when Bullet
// (Debian libbullet-dev) is found.
//
// Mapping of jelly's model onto Bullet:
//  * one node per particle at its position, with its mass; one link per spring (any type), its
//    rest length jelly's;
//  * a link's stiffness kLST (the fraction of its violation one iteration removes) is the one
//    XPBD's first iteration gives a spring of stiffness ks at the frame's step h between
//    particles of inverse masses wa + wb = w: kLST = ks h^2 w / (1 + ks h^2 w), one material per
//    spring type with w from the type's mean inverse masses;
//  * no damping (kDP = 0: jelly's dampers act along the springs, Bullet's kDP on the whole
//    velocity), friction kDF = 1 times each obstacle's kinetic friction mu;
//  * terrains: a sphere is a static btSphereShape, a plane a static box whose top face is the
//    plane (Bullet's soft-rigid collision takes convex shapes); the soft body's collision margin
//    is a quarter of its smallest rest length.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <numeric>
#include <vector>

#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>
#include <CLI/CLI.hpp>

#include <jelly/bench/output.hpp>
#include <jelly/bench/peer_budget.hpp>
#include <jelly/bench/run_info.hpp>
#include <jelly/core/errors.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/detail/obstacle.hpp>
#include <jelly/terrain/plane.hpp>

namespace jelly::bench {
namespace {

btVector3 to_bt(const Vec3& v) {
  return btVector3(static_cast<btScalar>(v.x()), static_cast<btScalar>(v.y()),
                   static_cast<btScalar>(v.z()));
}

class BulletRun final : public PeerRun {
 public:
  BulletRun(const Scene& scene, Real frame, int iterations)
      : dispatcher_(&config_),
        world_(&dispatcher_, &broadphase_, &solver_, &config_),
        frame_(frame) {
    const Simulator sim = make_simulator(scene);
    const Model& model = sim.model();
    const Vec3 g = model.gravity;
    world_.setGravity(to_bt(g));
    btSoftBodyWorldInfo& info = world_.getWorldInfo();
    info.m_gravity = to_bt(g);
    info.air_density = 0;
    info.m_sparsesdf.Initialize();
    for (const auto& terrain : sim.terrains()) add_terrain(*terrain);

    const int n = model.num_particles();
    std::vector<btVector3> x(n);
    std::vector<btScalar> m(n);
    for (int i = 0; i < n; ++i) {
      x[i] = to_bt(particle(sim.state().x, i));
      m[i] = static_cast<btScalar>(model.mass[i]);
    }
    soft_ = std::make_unique<btSoftBody>(&info, n, x.data(), m.data());
    const Springs& s = model.springs;
    std::vector<btSoftBody::Material*> material(kSpringTypeCount, nullptr);
    Real shortest = INFINITY;
    for (int t = 0; t < kSpringTypeCount; ++t) {
      Real ks = 0, w = 0;
      int count = 0;
      for (int k = 0; k < s.size(); ++k) {
        if (static_cast<int>(s.type[k]) != t) continue;
        ks += s.ks[k];
        w += 1 / model.mass[s.a[k]] + 1 / model.mass[s.b[k]];
        ++count;
      }
      if (count == 0) continue;
      ks /= count;
      w /= count;
      const Real c = ks * frame * frame * w;
      material[t] = soft_->appendMaterial();
      material[t]->m_kLST = static_cast<btScalar>(c / (1 + c));
      material[t]->m_kAST = 0;
      material[t]->m_kVST = 0;
      klst_.push_back(c / (1 + c));
    }
    for (int k = 0; k < s.size(); ++k) {
      soft_->appendLink(s.a[k], s.b[k], material[static_cast<int>(s.type[k])], false);
      soft_->m_links[soft_->m_links.size() - 1].m_rl = static_cast<btScalar>(s.rest_length[k]);
      shortest = std::min(shortest, s.rest_length[k]);
    }
    soft_->m_cfg.piterations = iterations;
    soft_->m_cfg.kDP = 0;
    soft_->m_cfg.kDF = 1;
    soft_->m_cfg.collisions = btSoftBody::fCollision::SDF_RS;
    soft_->getCollisionShape()->setMargin(static_cast<btScalar>(shortest / 4));
    soft_->updateConstants();
    world_.addSoftBody(soft_.get());
    positions_.setZero(3 * n);
  }
  ~BulletRun() override {
    world_.removeSoftBody(soft_.get());
    for (auto& body : bodies_) world_.removeRigidBody(body.get());
  }

  bool frame() override {
    world_.stepSimulation(static_cast<btScalar>(frame_), 1, static_cast<btScalar>(frame_));
    return true;
  }
  const VecX& positions() override {
    for (int i = 0; i < soft_->m_nodes.size(); ++i) {
      const btVector3& p = soft_->m_nodes[i].m_x;
      positions_.segment<3>(3 * i) = Vec3(p.x(), p.y(), p.z());
    }
    return positions_;
  }
  const std::vector<Real>& klst() const { return klst_; }

 private:
  void add_terrain(const Terrain& terrain) {
    btTransform pose;
    pose.setIdentity();
    std::unique_ptr<btCollisionShape> shape;
    if (const auto* obstacle = dynamic_cast<const Obstacle*>(&terrain);
        obstacle && obstacle->spec().geometry.shape == ObstacleShape::kSphere) {
      shape =
          std::make_unique<btSphereShape>(static_cast<btScalar>(obstacle->spec().geometry.radius));
      pose.setOrigin(to_bt(obstacle->spec().center));
    } else if (const auto* plane = dynamic_cast<const Plane*>(&terrain)) {
      // A box 100 m wide and 10 m deep whose top face is the plane.
      const Real half_depth = 5;
      shape = std::make_unique<btBoxShape>(btVector3(50, static_cast<btScalar>(half_depth), 50));
      const Vec3 up = plane->unit_normal();
      const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(Vec3::UnitY(), up);
      pose.setRotation(btQuaternion(static_cast<btScalar>(q.x()), static_cast<btScalar>(q.y()),
                                    static_cast<btScalar>(q.z()), static_cast<btScalar>(q.w())));
      pose.setOrigin(to_bt(plane->point() - half_depth * up));
    } else {
      throw InputError("terrain kind", std::string(terrain.kind()),
                       "a sphere or a plane (the Bullet driver maps no other)");
    }
    auto motion = std::make_unique<btDefaultMotionState>(pose);
    btRigidBody::btRigidBodyConstructionInfo ci(0, motion.get(), shape.get());
    auto body = std::make_unique<btRigidBody>(ci);
    body->setFriction(static_cast<btScalar>(terrain.contact().friction));
    world_.addRigidBody(body.get());
    shapes_.push_back(std::move(shape));
    motions_.push_back(std::move(motion));
    bodies_.push_back(std::move(body));
  }

  btSoftBodyRigidBodyCollisionConfiguration config_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  btSoftRigidDynamicsWorld world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btDefaultMotionState>> motions_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::unique_ptr<btSoftBody> soft_;
  Real frame_;
  VecX positions_;
  std::vector<Real> klst_;
};

}  // namespace
}  // namespace jelly::bench

int main(int argc, char** argv) {
  using namespace jelly;
  using namespace jelly::bench;
  CLI::App app("jelly-bench-bullet: the frame budget against Bullet's classic soft body");
  PeerBudgetOptions o;
  o.scenes_dir = JELLY_PEER_SCENES_DIR;
  o.reference = "bullet";
  int threads = 0, iterations = 10, converged_steps = 16, symplectic_steps = 32;
  IntegratorOptions jelly_options;
  std::vector<std::string> labels;
  std::string out = "out/bullet";
  app.add_option("--scenes", o.scenes, "cloth64 and/or cube20")->delimiter(',');
  app.add_option("--scenes-dir", o.scenes_dir, "folder of cloth_on_sphere.json, seed_slope.json");
  app.add_option("--duration", o.duration, "simulated time per run (s)");
  app.add_option("--rounds", o.rounds, "runs of every setup, in alternation");
  app.add_option("--threads", threads, "jelly's threads (0 = all cores)");
  app.add_option("--bullet-iterations", iterations, "Bullet's position iterations");
  app.add_option("--vbd-iterations", jelly_options.vbd.iterations, "vbd's sweeps per step");
  app.add_option("--vbd-chebyshev_rho", jelly_options.vbd.chebyshev_rho,
                 "vbd's Chebyshev rho (0 = off)");
  app.add_option("--vbd-contact_hardness", jelly_options.vbd.contact_hardness,
                 "vbd's contact hardness (0 = contact after the step)");
  app.add_option("--xpbd-substeps", jelly_options.xpbd.substeps, "xpbd's substeps per step");
  app.add_option("--converged-steps", converged_steps,
                 "rk4's steps per frame for the converged stretch (0 = no such setup)");
  app.add_option("--symplectic-steps", symplectic_steps,
                 "symplectic_euler's steps per frame (0 = no such setup)");
  app.add_option("--setups", labels, "only these setups (labels, comma-separated)")->delimiter(',');
  app.add_option("--out", out, "output folder (CSV, HDF5)");
  CLI11_PARSE(app, argc, argv);
  try {
    require(iterations >= 1 && iterations <= 1000, "--bullet-iterations", iterations,
            "an integer in [1, 1000]");
    require(threads >= 0, "--threads", threads, "an integer >= 0 (0 = all cores)");
    jelly_options.vbd.validate("--vbd-");
    jelly_options.xpbd.validate("--xpbd-");
    require(converged_steps >= 0 && converged_steps <= 10000, "--converged-steps", converged_steps,
            "an integer in [0, 10000] (0 = none)");
    require(symplectic_steps >= 0 && symplectic_steps <= 10000, "--symplectic-steps",
            symplectic_steps, "an integer in [0, 10000] (0 = none)");
    std::vector<PeerSetup> setups = default_jelly_peer_setups(threads, jelly_options);
    if (converged_steps > 0) {
      // The material's own stretch: rk4 at a small step (converged: docs/performance.md).
      o.converged = "rk4 x" + std::to_string(converged_steps);
      setups.push_back(
          jelly_peer_setup(o.converged, "rk4", jelly_options, threads, converged_steps));
    }
    if (symplectic_steps > 0) {
      setups.push_back(jelly_peer_setup("symplectic_euler x" + std::to_string(symplectic_steps),
                                        "symplectic_euler", jelly_options, threads,
                                        symplectic_steps));
    }
    PeerSetup bullet;
    bullet.label = "bullet";
    bullet.engine = "bullet 3.24 btSoftBody, " + std::to_string(iterations) + " iterations";
    bullet.make = [iterations](const Scene& scene, Real frame) {
      return std::unique_ptr<PeerRun>(new BulletRun(scene, frame, iterations));
    };
    setups.push_back(bullet);
    if (!labels.empty()) {
      std::string all;
      for (const PeerSetup& s : setups) all += (all.empty() ? "" : ", ") + s.label;
      for (const std::string& l : labels) {
        require(std::any_of(setups.begin(), setups.end(),
                            [&](const PeerSetup& s) { return s.label == l; }),
                "--setups", l, "labels among: " + all);
      }
      setups.erase(std::remove_if(setups.begin(), setups.end(),
                                  [&](const PeerSetup& s) {
                                    return std::find(labels.begin(), labels.end(), s.label) ==
                                           labels.end();
                                  }),
                   setups.end());
    }
    o.progress = &std::cerr;
    // Taken before the run: its date and load are the start's (write_outputs adds the end's).
    Metadata metadata = run_metadata(std::vector<std::string>(argv, argv + argc));
    const Table table = run_peer_budget(o, setups);
    write_outputs("bullet", {table}, metadata, out, Shard{}, std::cout);
  } catch (const InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
