#include "progress.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace jelly::cli {

namespace {
constexpr double kRedrawSeconds = 0.1;
constexpr int kBarWidth = 24;

std::string clock_text(double seconds) {
  if (!std::isfinite(seconds)) return "--:--";
  const long s = std::lround(std::max(0.0, seconds));
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%ld:%02ld", s / 60, s % 60);
  return buffer;
}
}  // namespace

void ProgressBar::on_frame(const Simulator& sim) {
  const Clock::time_point now = Clock::now();
  if (!started_) {
    started_ = true;
    start_ = last_draw_ = now;
    t_start_ = sim.state().t;
    steps_start_ = sim.total_steps();
    return;
  }
  if (std::chrono::duration<double>(now - last_draw_).count() < kRedrawSeconds) return;
  last_draw_ = now;
  draw(sim, now);
}

void ProgressBar::on_finish(const Simulator& sim, const RunReport& /*report*/) {
  if (!started_) return;
  draw(sim, Clock::now());
  std::fputc('\n', out_);
  std::fflush(out_);
}

void ProgressBar::draw(const Simulator& sim, Clock::time_point now) {
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const Real t = sim.state().t;
  const Real span = t_end_ - t_start_;
  const double fraction = span > 0 ? std::clamp((t - t_start_) / span, 0.0, 1.0) : 1.0;
  const double steps_per_second =
      elapsed > 0 ? static_cast<double>(sim.total_steps() - steps_start_) / elapsed : 0;
  // Time left at the average simulated-time rate so far.
  const double eta = fraction > 0 ? elapsed * (1 - fraction) / fraction : INFINITY;
  const int filled = static_cast<int>(std::lround(fraction * kBarWidth));
  const std::string bar = std::string(filled, '#') + std::string(kBarWidth - filled, '-');
  std::fprintf(out_, "\r[%s] %3d%%  t = %.3f / %.3f s  %.0f steps/s  ETA %s\x1b[K", bar.c_str(),
               static_cast<int>(fraction * 100), t, t_end_, steps_per_second,
               clock_text(eta).c_str());
  std::fflush(out_);
}

}  // namespace jelly::cli
