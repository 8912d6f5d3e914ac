// The team size of each step of a run with the default thread count
// (core/detail/team_chooser.hpp), fed synthetic step times: no clock is read.
#include <gtest/gtest.h>

#include <functional>

#include <jelly/core/detail/team_chooser.hpp>

namespace jelly {
namespace {

// No other runnable thread on the machine.
int no_others() { return 0; }

using StepTime = std::function<double(long step, int threads)>;

// Runs `steps` steps whose times step_time gives; returns their total time.
double run(parallel::TeamChooser& chooser, long first, long steps, const StepTime& step_time) {
  double total = 0;
  for (long k = first; k < first + steps; ++k) {
    const double seconds = step_time(k, chooser.threads());
    total += seconds;
    chooser.record(seconds);
  }
  return total;
}

// A machine where one thread takes `one` seconds per step and two threads `two`.
StepTime machine(double one, double two) {
  return [one, two](long, int threads) { return threads > 1 ? two : one; };
}

TEST(TeamChooser, OneCoreIsOneThread) {
  parallel::TeamChooser chooser(1, no_others);
  run(chooser, 0, 100, machine(1.0, 0.5));
  EXPECT_EQ(chooser.threads(), 1);
  EXPECT_EQ(chooser.steps_on_all_cores(), 0);
}

TEST(TeamChooser, QuietMachineRunsOnAllCores) {
  parallel::TeamChooser chooser(2, no_others);
  const double total = run(chooser, 0, 2000, machine(1.8e-3, 1.0e-3));
  EXPECT_EQ(chooser.threads(), 2);
  // The trials of one thread cost a few percent at most.
  EXPECT_LT(total, 1.03 * 2000 * 1.0e-3);
  EXPECT_GT(chooser.steps_on_all_cores(), 0.97 * 2000);
}

TEST(TeamChooser, BusyNeighbourRunsOnOneThread) {
  parallel::TeamChooser chooser(2, no_others);
  // Two threads five times slower than one.
  const double total = run(chooser, 0, 2000, machine(1.0e-3, 5.0e-3));
  EXPECT_EQ(chooser.threads(), 1);
  EXPECT_LT(total, 1.05 * 2000 * 1.0e-3);
}

TEST(TeamChooser, EqualSpeedsKeepTheChoice) {
  parallel::TeamChooser chooser(2, no_others);
  run(chooser, 0, 500, machine(1.0e-3, 1.0e-3));
  // Tried, but not chosen: not faster by the margin.
  EXPECT_GT(chooser.steps_on_all_cores(), 0);
  EXPECT_LT(chooser.steps_on_all_cores(), 0.5 * 500);
}

TEST(TeamChooser, FollowsTheLoad) {
  parallel::TeamChooser chooser(2, no_others);
  const StepTime quiet = machine(1.8e-3, 1.0e-3), busy = machine(1.0e-3, 5.0e-3);
  run(chooser, 0, 1000, quiet);
  ASSERT_EQ(chooser.threads(), 2);
  // A neighbour starts: a slow step calls a trial, one thread within a few steps.
  long steps = 0;
  for (; chooser.threads() != 1 || steps < 1; ++steps) run(chooser, 1000 + steps, 1, busy);
  EXPECT_LE(steps,
            parallel::TeamChooser::kMinStepsBetweenTrials + parallel::TeamChooser::kTrialSteps + 1);
  const double busy_total = run(chooser, 2000, 2000, busy);
  EXPECT_LT(busy_total, 1.05 * 2000 * 1.0e-3);
  // It stops: back on all cores within the patience for one thread's trials.
  const long before = chooser.steps();
  while (chooser.threads() != 2 || chooser.steps() == before) run(chooser, 5000, 1, quiet);
  EXPECT_LT(chooser.steps() - before, 1000);
}

int others_now = 0;
int others() { return others_now; }

TEST(TeamChooser, NoTrialWhileOthersRun) {
  parallel::TeamChooser chooser(2, others);
  others_now = 1;
  run(chooser, 0, 1000, machine(1.8e-3, 1.0e-3));
  EXPECT_EQ(chooser.steps_on_all_cores(), 0);
  // They stop: the next check starts a trial, and all cores win.
  others_now = 0;
  run(chooser, 1000, 100, machine(1.8e-3, 1.0e-3));
  EXPECT_EQ(chooser.threads(), 2);
}

TEST(TeamChooser, LostTrialEndsAtOnce) {
  parallel::TeamChooser chooser(2, no_others);
  // Two threads thirty times slower: a trial is one step.
  run(chooser, 0, 2000, machine(1.0e-3, 30.0e-3));
  EXPECT_EQ(chooser.threads(), 1);
  EXPECT_LT(chooser.steps_on_all_cores(), 10);
}

TEST(TeamChooser, SameInputsSameChoices) {
  // Step times that vary (a slow step now and then): two choosers choose alike.
  const StepTime varying = [](long k, int threads) {
    return (threads > 1 ? 1.0e-3 : 1.7e-3) * (k % 37 == 0 ? 3.0 : 1.0);
  };
  parallel::TeamChooser a(2, no_others), b(2, no_others);
  for (long k = 0; k < 3000; ++k) {
    ASSERT_EQ(a.threads(), b.threads()) << k;
    const double seconds = varying(k, a.threads());
    a.record(seconds);
    b.record(seconds);
  }
  EXPECT_GT(a.steps_on_all_cores(), 0.9 * 3000);
}

}  // namespace
}  // namespace jelly
