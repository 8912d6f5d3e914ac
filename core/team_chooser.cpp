#include <jelly/core/detail/team_chooser.hpp>

#include <algorithm>
#include <cmath>

namespace jelly::parallel {

TeamChooser::TeamChooser(int cores) : cores_(std::max(1, cores)) {}

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
  if (threads() > 1 && !team_started_) {
    team_started_ = true;
    return;
  }
  if (in_trial_) {
    trial_seconds_ += seconds;
    if (++trial_steps_ < kTrialSteps || trial_seconds_ < kTrialSeconds) return;
    in_trial_ = false;
    const double trial_mean = trial_seconds_ / trial_steps_;
    if (trial_mean < (1 - kMargin) * chosen_mean_) {
      chosen_ = other();
      chosen_mean_ = trial_mean;
      patience_ = kPatience;
      wait_seconds_ = 0;
    } else {
      // The trial's loss against the chosen size, times the patience.
      const double loss = std::min(
          4 * trial_steps_ * chosen_mean_,
          std::max(kMargin * trial_seconds_, trial_seconds_ - trial_steps_ * chosen_mean_));
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
      (slow_steps_ >= kSlowSteps || chosen_seconds_ >= wait_seconds_))
    start_trial();
}

}  // namespace jelly::parallel
