#pragma once
// A one-line progress bar on a terminal: simulated time, steps per second and the time left,
// redrawn at most 10 times a second from the simulator's frames.
#include <chrono>
#include <cstdio>

#include <jelly/solvers/simulator.hpp>

namespace jelly::cli {

class ProgressBar final : public Observer {
 public:
  // Draws on `out` (a terminal) for a run from the simulator's current time to t_end.
  ProgressBar(std::FILE* out, Real t_end) : out_(out), t_end_(t_end) {}

  void on_frame(const Simulator& sim) override;
  void on_finish(const Simulator& sim, const RunReport& report) override;

 private:
  using Clock = std::chrono::steady_clock;
  void draw(const Simulator& sim, Clock::time_point now);

  std::FILE* out_;
  Real t_end_;
  bool started_ = false;
  Clock::time_point start_, last_draw_;
  Real t_start_ = 0;
  long steps_start_ = 0;
};

}  // namespace jelly::cli
