#pragma once
// The team size of each step of a run with the default thread count (docs/threads.md, "Threads
// that never hurt"): all cores or one thread, whichever ran recent steps faster. With a busy
// neighbour on the cores, a team's threads wait for each other's time slices and more threads
// can be many times slower than one; on a quiet machine the team is faster. Neither is assumed:
// the chooser runs a few steps of the other size now and then and keeps the faster. Results do
// not depend on the choice (every threaded loop gives the same bits for any team size).
namespace jelly::parallel {

class TeamChooser {
 public:
  // Steps of the other size in one trial, at least, and their time, at least (so that one time
  // slice lost to another process does not decide a trial of short steps).
  static constexpr int kTrialSteps = 2;
  static constexpr double kTrialSeconds = 0.01;
  // Steps of the chosen size between two trials, at least (and before the first trial).
  static constexpr int kMinStepsBetweenTrials = 4;
  // The other size must be this much faster (a fraction of the chosen size's step time) to be
  // chosen: equal speeds keep the choice.
  static constexpr double kMargin = 0.03;
  // After a trial, the chosen size runs `patience` times the time the trial lost before the next
  // one (so trials cost at most about 1 / patience of the run). The loss counted is at least
  // kMargin of the trial. Each trial that confirms the choice doubles the patience, up to the
  // largest for that choice; a change of choice resets it.
  static constexpr double kPatience = 50;
  static constexpr double kLargestPatienceAllCores = 800;  // slow steps call a trial at once
  static constexpr double kLargestPatienceOneThread = 100;
  // On all cores, kSlowSteps steps in a row each this many times slower than the recent ones
  // call a trial at once (a neighbour that starts on the cores slows the team down several
  // times; one slow step is more often a time slice lost once).
  static constexpr double kSlowStep = 1.5;
  static constexpr int kSlowSteps = 2;

  // A trial that has taken this many times the chosen size's time for kTrialSteps steps has
  // lost and ends at once (a team on contended cores can be tens of times slower).
  static constexpr double kLostTrial = 2;

  // The number of threads of other processes (or of this one) that were runnable besides the
  // caller when asked, or -1 when not known.
  using OthersRunning = int (*)();
  // The machine's count (/proc/stat's procs_running, less the caller): read when a trial on all
  // cores is due (at most every kMinStepsBetweenTrials steps and kTrialSeconds), never per region.
  static int others_running();

  // `cores`: the largest team (parallel::available_cores()); 1 disables the choice. No trial on
  // all cores starts while `others` says another thread is runnable (it would run on the core
  // the team needs); a trial costs steps, the check one file read.
  explicit TeamChooser(int cores, OthersRunning others = &TeamChooser::others_running);

  // The team size for the next step: 1 or `cores`.
  int threads() const { return in_trial_ ? other() : chosen_; }
  // The wall time of the step just run on threads() threads.
  void record(double seconds);

  // Steps recorded, and those of them on all cores.
  long steps() const { return steps_; }
  long steps_on_all_cores() const { return steps_on_all_cores_; }

 private:
  int other() const { return chosen_ == 1 ? cores_ : 1; }
  void start_trial();

  int cores_;
  OthersRunning others_;
  int chosen_ = 1;             // the size of the steps between trials (1 until measured)
  bool warm_ = false;          // the first step (allocations, analyses) is not compared
  double chosen_mean_ = 0;     // moving average of the chosen size's step times (0: none yet)
  long chosen_steps_ = 0;      // steps of the chosen size since the last trial
  double chosen_seconds_ = 0;  // their time
  double wait_seconds_ = 0;    // the chosen size's time before the next trial
  double patience_ = kPatience;
  int slow_steps_ = 0;  // slow steps in a row on all cores
  bool in_trial_ = false;
  int trial_steps_ = 0;
  double trial_seconds_ = 0;
  long steps_ = 0, steps_on_all_cores_ = 0;
};

}  // namespace jelly::parallel
