#pragma once
// A model's cost per servo step as a study reports it (docs/studies.md, "Costs"): measured in a
// timing pass of its own, after every accuracy run of the study is over, each model run alone —
// nothing else of the study running — and repeated. The models are timed in turn: round r runs
// every model once, so that a slow spell of the machine (another process, the hypervisor) falls on
// one run of each model that it overlaps, not on all the runs of one, and the median over the runs
// leaves it out. A step's cost is its wall time (run_model's cost_s); one run gives the median,
// p99 and max over its steps; the study reports the median over the runs of each, and the spread
// of the runs' p99 (their smallest and largest), so that a reader sees how far a second
// measurement may move it. A run passes at least `timing_min_steps` steps: a shorter trajectory is
// passed several times within one run, so that its p99 is not the 6th or the 14th largest of a
// few hundred steps but stands on ≥ 50 of them.

#include "formats/profile/force_profile.hpp"

#include <cstddef>
#include <functional>
#include <vector>

namespace kerf {

/// The cost per step of repeated, undisturbed runs of one model.
struct TimedCost {
  int runs = 0;             ///< whole runs timed
  std::size_t steps = 0;    ///< servo steps per run
  double median = 0.0;      ///< median over the runs of each run's median step cost [s]
  double p99 = 0.0;         ///< median over the runs of each run's 99th-percentile step cost [s]
  double p99_low = 0.0;     ///< the smallest p99 of the runs [s]
  double p99_high = 0.0;    ///< the largest p99 of the runs [s]
  double max = 0.0;         ///< median over the runs of each run's largest step cost [s]
  /// Every timed run gave the forces of the scored profile (bit for bit, when one was given to
  /// compare): the costs are those of the run that was scored.
  bool reproduces_scored_run = true;
  /// The servo rate the p99 cost allows [Hz] (1 / p99).
  [[nodiscard]] double rate_allowed() const { return p99 > 0.0 ? 1.0 / p99 : 0.0; }
  /// (p99_high − p99_low) / p99: the spread of the runs' p99 relative to the reported one.
  [[nodiscard]] double p99_spread() const { return p99 > 0.0 ? (p99_high - p99_low) / p99 : 0.0; }
};

/// Times `run` (a whole run of one model along its trajectories, returning its profile with the
/// cost of every step) `repeats` >= 1 times, one after another on the calling thread, and
/// summarises the costs (see file comment). With `scored`, each run's forces are compared with it.
/// Throws std::invalid_argument for repeats < 1, std::runtime_error for a run without steps.
TimedCost time_model_runs(const std::function<ForceProfile()>& run, int repeats, const ForceProfile* scored = nullptr);

/// Servo steps a timed run passes at least: its p99 then stands on the 50 slowest steps or more.
inline constexpr std::size_t timing_min_steps = 5000;

/// Passes of a trajectory of `steps` servo steps that make one timed run: ⌈timing_min_steps / steps⌉.
[[nodiscard]] int passes_per_timed_run(std::size_t steps);

/// One model of a timing pass: its whole run along its trajectories, the profile that was scored
/// (or nullptr), and how many times one timed run passes the trajectories (their step costs
/// pooled into the run's statistics).
struct TimedModel {
  std::function<ForceProfile()> run;
  const ForceProfile* scored = nullptr;
  int passes = 1;
};

/// Times every model `repeats` >= 1 times in turn on the calling thread — round 1 runs models
/// 0, 1, …, n−1, then round 2, … — and summarises each model's runs as time_model_runs does; a
/// model's run calls its `run` `passes` times and pools the step costs. `steps` is then the
/// steps of one run, all passes together.
/// `round_done(r, seconds)`, if given, is called after round r (1-based) with its wall time.
/// Throws as time_model_runs.
std::vector<TimedCost> time_models_in_turn(const std::vector<TimedModel>& models, int repeats,
                                           const std::function<void(int round, double seconds)>& round_done = {});

} // namespace kerf
