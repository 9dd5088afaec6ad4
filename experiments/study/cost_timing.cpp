#include "experiments/study/cost_timing.hpp"

#include "experiments/models/run_model.hpp"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

namespace kerf {

namespace {

/// The median of `v` (the mean of the two middle values for an even count); v is reordered.
double median_of(std::vector<double> v) {
  const std::size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2), v.end());
  const double upper = v[n / 2];
  if (n % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n / 2)));
}

bool same_forces(const ForceProfile& a, const ForceProfile& b) {
  if (a.rows.size() != b.rows.size()) return false;
  for (std::size_t k = 0; k < a.rows.size(); ++k)
    if (a.rows[k].force != b.rows[k].force || a.rows[k].t != b.rows[k].t) return false;
  return true;
}

} // namespace

int passes_per_timed_run(std::size_t steps) {
  if (steps == 0) return 1;
  return static_cast<int>((timing_min_steps + steps - 1) / steps);
}

TimedCost time_model_runs(const std::function<ForceProfile()>& run, int repeats, const ForceProfile* scored) {
  return time_models_in_turn({TimedModel{run, scored}}, repeats).front();
}

std::vector<TimedCost> time_models_in_turn(const std::vector<TimedModel>& models, int repeats,
                                           const std::function<void(int round, double seconds)>& round_done) {
  if (repeats < 1) throw std::invalid_argument("timing: at least one run, got " + std::to_string(repeats));
  struct Runs {
    std::vector<double> medians, p99s, maxima;
  };
  std::vector<Runs> runs(models.size());
  std::vector<TimedCost> out(models.size());
  for (int r = 0; r < repeats; ++r) {
    const auto begin = std::chrono::steady_clock::now();
    for (std::size_t m = 0; m < models.size(); ++m) {
      std::vector<double> costs;
      for (int pass = 0; pass < std::max(1, models[m].passes); ++pass) {
        const ForceProfile profile = models[m].run();
        const std::vector<double> c = step_costs(profile);
        if (c.empty()) throw std::runtime_error("timing: the run has no steps");
        costs.insert(costs.end(), c.begin(), c.end());
        if (models[m].scored && !same_forces(profile, *models[m].scored)) out[m].reproduces_scored_run = false;
      }
      const CostStatistics c = cost_statistics(std::move(costs));
      out[m].steps = c.steps;
      runs[m].medians.push_back(c.median);
      runs[m].p99s.push_back(c.p99);
      runs[m].maxima.push_back(c.max);
    }
    if (round_done) round_done(r + 1, std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count());
  }
  for (std::size_t m = 0; m < models.size(); ++m) {
    TimedCost& t = out[m];
    t.runs = repeats;
    t.median = median_of(runs[m].medians);
    t.p99 = median_of(runs[m].p99s);
    t.max = median_of(runs[m].maxima);
    t.p99_low = *std::min_element(runs[m].p99s.begin(), runs[m].p99s.end());
    t.p99_high = *std::max_element(runs[m].p99s.begin(), runs[m].p99s.end());
  }
  return out;
}

} // namespace kerf
