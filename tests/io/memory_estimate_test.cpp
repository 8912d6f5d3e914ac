// The run limits' memory estimate against the memory a run really takes (issue 44): each
// integrator runs a few steps of a body in a child process, which reports the growth of its peak
// resident size (VmHWM) over its resident size before the body was built; the estimate's growth
// over an empty scene must be within a factor of 2 of it, at two sizes, and so must the growth
// from the smaller size to the larger (the estimate's slope, what decides at large sizes).
#include <jelly/io/detail/memory_estimate.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include <jelly/io/detail/run_limits.hpp>
#include <jelly/io/scene.hpp>

namespace jelly {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

// A field of /proc/self/status in bytes ("VmRSS", "VmHWM"), or -1.
double status_bytes(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key + ":", 0) == 0) return std::atof(line.c_str() + key.size() + 1) * 1024;
  }
  return -1;
}

// The growth of the peak resident size while a child process builds the scene's simulator and
// takes three steps, in bytes; -1 when it cannot be measured (no /proc, the reset refused).
double measured_growth(const std::string& scene_json) {
  int fds[2];
  if (pipe(fds) != 0) return -1;
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    double growth = -1;
    try {
      const Scene scene = parse_scene(scene_json);
      std::ofstream("/proc/self/clear_refs") << "5";  // VmHWM := VmRSS
      const double before = status_bytes("VmRSS");
      const double reset = status_bytes("VmHWM");
      if (before > 0 && reset <= before * 1.05) {
        Simulator sim = make_simulator(scene);
        for (int i = 0; i < 3; ++i) sim.step();
        growth = status_bytes("VmHWM") - before;
      }
    } catch (...) {
      growth = -2;
    }
    const ssize_t written = write(fds[1], &growth, sizeof growth);
    _exit(written == sizeof growth ? 0 : 1);
  }
  close(fds[1]);
  double growth = -1;
  if (pid < 0 || read(fds[0], &growth, sizeof growth) != sizeof growth) growth = -1;
  close(fds[0]);
  if (pid > 0) waitpid(pid, nullptr, 0);
  return growth;
}

// The estimate's part that grows with the scene's bodies.
double estimated_growth(const std::string& scene_json) {
  const RunEstimate e = estimate_run(parse_scene(scene_json));
  return e.memory_bytes -
         estimate_memory_bytes(0, 0, parse_scene(scene_json).integrator.name, false);
}

std::string cube_scene(int n, const std::string& integrator) {
  return R"({"cube": {"n": )" + std::to_string(n) +
         R"(, "edge_length": 4}, "terrains": [{"kind": "slope"}],
             "integrator": {"name": ")" +
         integrator + R"(", "dt": 0.001}, "duration": 1})";
}

std::string cloth_scene(int n, const std::string& integrator) {
  const std::string nu = std::to_string(n);
  return R"({"bodies": [{"kind": "cloth", "name": "cloth", "nu": )" + nu + R"(, "nv": )" + nu +
         R"(, "size_u": 2, "size_v": 2, "position": [0, 3, 0], "density": 0.3,
               "springs": {"structural": {"ks": 60, "kd": 0.05}, "shear": {"ks": 20, "kd": 0.02},
                           "bending": {"ks": 2, "kd": 0.002}}}],
             "terrains": [], "integrator": {"name": ")" +
         integrator + R"(", "dt": 0.001}, "duration": 1})";
}

// Checks the estimate against the measured growth at the sizes small and large of `scene`.
void expect_within_2x(const std::string& what, const std::string& small, const std::string& large) {
  const double m_small = measured_growth(small), m_large = measured_growth(large);
  if (m_small == -1 || m_large == -1) GTEST_SKIP() << "no /proc/self peak reset here";
  ASSERT_GT(m_small, 0) << what << ": the child process failed";
  ASSERT_GT(m_large, 0) << what << ": the child process failed";
  const double e_small = estimated_growth(small), e_large = estimated_growth(large);
  const auto report = [&](const char* part, double estimated, double measured) {
    return what + " " + part + ": estimated " + bytes_text(estimated) + ", measured " +
           bytes_text(measured);
  };
  std::printf("%s\n%s\n", report("small", e_small, m_small).c_str(),
              report("large", e_large, m_large).c_str());
  EXPECT_LE(e_large, 2 * m_large) << report("large", e_large, m_large);
  EXPECT_GE(e_large, 0.5 * m_large) << report("large", e_large, m_large);
  EXPECT_LE(e_small, 2 * m_small) << report("small", e_small, m_small);
  EXPECT_GE(e_small, 0.5 * m_small) << report("small", e_small, m_small);
  const double e_slope = e_large - e_small, m_slope = m_large - m_small;
  EXPECT_LE(e_slope, 2 * m_slope) << report("small to large", e_slope, m_slope);
  EXPECT_GE(e_slope, 0.5 * m_slope) << report("small to large", e_slope, m_slope);
}

class MemoryEstimateOf : public ::testing::TestWithParam<std::string> {};

TEST_P(MemoryEstimateOf, ACubeWithinTwiceTheMeasuredPeak) {
  if (kSanitized) GTEST_SKIP() << "the sanitizers' allocator changes the resident size";
  expect_within_2x(GetParam() + ", cube", cube_scene(14, GetParam()), cube_scene(24, GetParam()));
}

TEST_P(MemoryEstimateOf, AClothWithinTwiceTheMeasuredPeak) {
  if (kSanitized) GTEST_SKIP() << "the sanitizers' allocator changes the resident size";
  expect_within_2x(GetParam() + ", cloth", cloth_scene(50, GetParam()),
                   cloth_scene(120, GetParam()));
}

INSTANTIATE_TEST_SUITE_P(EveryIntegrator, MemoryEstimateOf,
                         ::testing::Values("explicit_euler", "symplectic_euler", "midpoint", "rk4",
                                           "xpbd", "arkode_erk", "implicit_euler",
                                           "projective_dynamics", "arkode_dirk"),
                         [](const auto& param_info) { return param_info.param; });

}  // namespace
}  // namespace jelly
