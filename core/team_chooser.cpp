#include <jelly/core/detail/team_chooser.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace jelly::parallel {

TeamChooser::TeamChooser(int cores, OthersRunning others)
    : cores_(std::max(1, cores)), others_(others) {}

int TeamChooser::others_running() {
  std::FILE* stat = std::fopen("/proc/stat", "r");
  if (stat == nullptr) return -1;
  int running = -1;
  char line[256];
  while (std::fgets(line, sizeof line, stat) != nullptr) {
    if (std::strncmp(line, "procs_running ", 14) == 0) {
      running = std::atoi(line + 14);
      break;
    }
  }
  std::fclose(stat);
  return running > 0 ? running - 1 : -1;
}

void TeamChooser::start_trial() {
  in_trial_ = true;
  trial_steps_ = 0;
  trial_seconds_ = 0;
}

void TeamChooser::record(double seconds) {
  ++steps_;
  if (threads() > 1) ++steps_on_all_cores_;
  if (cores_ <= 1 || !(seconds >= 0) || !std::isfinite(seconds)) return;
  if (!warm_) {
    warm_ = true;
    return;
  }
  if (in_trial_) {
    trial_seconds_ += seconds;
    ++trial_steps_;
    const bool lost = trial_seconds_ >= kLostTrial * kTrialSteps * chosen_mean_;
    if (!lost && (trial_steps_ < kTrialSteps || trial_seconds_ < kTrialSeconds)) return;
    in_trial_ = false;
    const double trial_mean = trial_seconds_ / trial_steps_;
    if (trial_mean < (1 - kMargin) * chosen_mean_) {
      chosen_ = other();
      chosen_mean_ = trial_mean;
      patience_ = kPatience;
      wait_seconds_ = 0;
    } else {
      // The trial's loss against the chosen size (at least kMargin of it), times the patience.
      const double loss =
          std::max(kMargin * trial_seconds_, trial_seconds_ - trial_steps_ * chosen_mean_);
      wait_seconds_ = patience_ * loss;
      const double largest = chosen_ == 1 ? kLargestPatienceOneThread : kLargestPatienceAllCores;
      patience_ = std::min(largest, 2 * patience_);
    }
    chosen_steps_ = 0;
    chosen_seconds_ = 0;
    return;
  }
  const bool slow = chosen_ > 1 && chosen_mean_ > 0 && seconds > kSlowStep * chosen_mean_;
  slow_steps_ = slow ? slow_steps_ + 1 : 0;
  chosen_mean_ = chosen_mean_ > 0 ? chosen_mean_ + 0.25 * (seconds - chosen_mean_) : seconds;
  ++chosen_steps_;
  chosen_seconds_ += seconds;
  if (chosen_steps_ >= kMinStepsBetweenTrials &&
      (slow_steps_ >= kSlowSteps || chosen_seconds_ >= wait_seconds_)) {
    // A team on all cores would share them with the threads already runnable.
    if (chosen_ == 1 && others_ != nullptr && others_() > 0) {
      // Asks again after kMinStepsBetweenTrials steps and kTrialSeconds.
      chosen_steps_ = 0;
      wait_seconds_ = chosen_seconds_ + kTrialSeconds;
      return;
    }
    start_trial();
  }
}

}  // namespace jelly::parallel
