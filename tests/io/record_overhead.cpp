// Measures what recording costs a run: the seed scene (n = 10 cube, 1000 particles, 12,876
// springs, on the 20-degree slope), rk4 at dt = 0.001, a frame every 1/60 s, for 3 s of simulated
// time; wall time, CPU time of the run's thread and CPU time of the process, without a recorder
// and with one in each configuration. Prints a table; not a test (tests never assert on time).
//   build/tests/io/jelly_record_overhead [seconds] [repeats] [output dir]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include <sys/resource.h>
#include <time.h>

#include <jelly/geometry/cube.hpp>
#include <jelly/io/h5_recorder.hpp>
#include <jelly/solvers/integrators/registry.hpp>
#include <jelly/terrain/plane.hpp>

namespace {

// CPU seconds of the calling thread: the simulation's critical path (with a free core, the wall
// time of the run follows it; a background writer's work is not in it).
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

// CPU seconds of the whole process, every thread included.
double cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

jelly::Simulator seed_slope() {
  const jelly::Model model = jelly::build_cube(jelly::CubeSpec{});
  jelly::SimulatorOptions options;
  options.dt = 0.001;
  options.output_interval = 1.0 / 60;
  jelly::Simulator sim(model, jelly::rest_state(model), jelly::make_integrator("rk4"), options);
  sim.add_terrain(std::make_unique<jelly::Plane>(jelly::Plane::slope(20)));
  return sim;
}

struct Config {
  const char* name;
  bool record;
  bool background;
  int compression;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "--help") {
    std::printf("usage: %s [seconds] [repeats] [directory]\n", argv[0]);
    return 0;
  }
  const double seconds = argc > 1 ? std::atof(argv[1]) : 3.0;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 3;
  const std::string dir = argc > 3 ? argv[3] : std::filesystem::temp_directory_path().string();
  const std::string path = dir + "/jelly_overhead.h5";
  const Config configs[] = {{"no recorder", false, false, 0},
                            {"background writer, deflate 4 (default)", true, true, 4},
                            {"background writer, deflate 1", true, true, 1},
                            {"background writer, no compression", true, true, 0},
                            {"inline writer, deflate 4", true, false, 4},
                            {"inline writer, no compression", true, false, 0}};
  std::printf(
      "seed slope, 1000 particles, rk4 dt 0.001, 60 frames/s, %.1f s simulated, best of %d\n",
      seconds, repeats);
  double baseline = 0, baseline_cpu = 0, baseline_main = 0;
  for (const Config& c : configs) {
    double best = 1e30, best_cpu = 1e30, best_main = 1e30;
    long frames = 0;
    std::uintmax_t bytes = 0;
    for (int r = 0; r < repeats; ++r) {
      jelly::Simulator sim = seed_slope();
      const auto start = std::chrono::steady_clock::now();
      const double cpu_start = cpu_seconds(), main_start = thread_cpu_seconds();
      {
        std::unique_ptr<jelly::H5Recorder> recorder;
        if (c.record) {
          jelly::RecorderOptions options;
          options.background_writer = c.background;
          options.compression_level = c.compression;
          options.overwrite = true;  // its own scratch file, from the configuration before
          recorder = std::make_unique<jelly::H5Recorder>(path, sim, options);
          sim.add_observer(*recorder);
        }
        sim.run_until(seconds);
        if (recorder) frames = recorder->frames();
      }  // the recorder's destructor closes the file: inside the timing
      const std::chrono::duration<double> wall = std::chrono::steady_clock::now() - start;
      best = std::min(best, wall.count());
      best_cpu = std::min(best_cpu, cpu_seconds() - cpu_start);
      best_main = std::min(best_main, thread_cpu_seconds() - main_start);
      if (c.record) bytes = std::filesystem::file_size(path);
    }
    if (!c.record) {
      baseline = best;
      baseline_cpu = best_cpu;
      baseline_main = best_main;
    }
    std::printf(
        "%-40s wall %6.3f s %+6.1f %% | run thread cpu %6.3f s %+6.1f %% | all cpu %6.3f s %+6.1f "
        "%%",
        c.name, best, 100 * (best / baseline - 1), best_main, 100 * (best_main / baseline_main - 1),
        best_cpu, 100 * (best_cpu / baseline_cpu - 1));
    if (c.record) {
      std::printf(" | per frame: run thread %+.3f ms, all %+.3f ms | %ld frames %.1f MB",
                  1e3 * (best_main - baseline_main) / frames,
                  1e3 * (best_cpu - baseline_cpu) / frames, frames, bytes / 1e6);
    }
    std::printf("\n");
  }
  std::filesystem::remove(path);
  std::filesystem::remove(dir + "/jelly_overhead.xdmf");
  return 0;
}
