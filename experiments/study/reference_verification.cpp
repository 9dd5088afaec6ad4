#include "experiments/study/reference_verification.hpp"

#include "formats/profile/profile_metrics.hpp"
#include "experiments/study/study_runner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace kerf {

namespace {

/// Finest first.
std::vector<const ReferenceLevel*> by_element_size(const std::vector<ReferenceLevel>& levels) {
  std::vector<const ReferenceLevel*> sorted;
  for (const ReferenceLevel& l : levels) sorted.push_back(&l);
  std::sort(sorted.begin(), sorted.end(), [](const ReferenceLevel* a, const ReferenceLevel* b) { return a->element_size < b->element_size; });
  return sorted;
}

/// The row of `rows` at time t (to 1e-9 s), or null.
const ProfileRow* at_time(const std::vector<const ProfileRow*>& rows, double t) {
  const auto it = std::lower_bound(rows.begin(), rows.end(), t - 1e-9, [](const ProfileRow* r, double v) { return r->t < v; });
  return it != rows.end() && (*it)->t <= t + 1e-9 ? *it : nullptr;
}

std::string describe(const char* name, double value, const GridConvergence& c) {
  char text[400];
  if (!c.usable()) {
    std::snprintf(text, sizeof text, "no GCI on %s = %.3g N: %s", name, value, c.unusable.c_str());
    return text;
  }
  std::snprintf(text, sizeof text, "GCI %.2g %% on %s = %.3g N (p = %.2g%s, extrapolated %.3g N)", 100.0 * *c.gci_fine, name, value,
                *c.observed_order, c.oscillatory ? ", oscillatory convergence" : "", *c.extrapolated);
  return text;
}

std::string format_order(double p) {
  char text[32];
  std::snprintf(text, sizeof text, "the formal %.2g", p);
  return text;
}

} // namespace

std::optional<double> ReferenceVerification::rms_uncertainty() const {
  if (!rms.usable()) return std::nullopt;
  return *rms.gci_fine * std::abs(rms_force);
}

std::optional<double> ReferenceVerification::peak_uncertainty() const {
  if (!peak.usable()) return std::nullopt;
  return *peak.gci_fine * std::abs(peak_force);
}

std::string ReferenceVerification::summary() const {
  char where[200];
  std::snprintf(where, sizeof where, "; from L%d, L%d, L%d (h = %.3g, %.3g, %.3g mm) on %zu common samples", levels[0], levels[1], levels[2],
                element_sizes[0] * 1e3, element_sizes[1] * 1e3, element_sizes[2] * 1e3, samples);
  char text[400];
  if (profile.usable() && peak_force > 0.0)
    std::snprintf(text, sizeof text, "uncertainty %.2g %% of the peak on the force profile (%.3g N RMS; level differences %.3g, %.3g N RMS, p = %.2g%s); ",
                  100.0 * *profile.uncertainty / peak_force, *profile.uncertainty, profile.e21, profile.e32, *profile.observed_order,
                  *profile.order_used < *profile.observed_order ? (", used " + format_order(*profile.order_used)).c_str() : "");
  else
    std::snprintf(text, sizeof text, "no uncertainty on the force profile: %s; ",
                  profile.usable() ? "the finest level has no force" : profile.unusable.c_str());
  return text + describe("RMS |F|", rms_force, rms) + "; " + describe("peak |F|", peak_force, peak) + where;
}

std::optional<ReferenceVerification> verify_reference(const std::vector<ReferenceLevel>& levels, const std::string& tool,
                                                      double formal_order) {
  if (levels.size() < 3) return std::nullopt;
  const auto sorted = by_element_size(levels);
  // The samples all three finest levels solved.
  ForceProfile common[3] = {sorted[0]->profile, sorted[1]->profile, sorted[2]->profile};
  for (int pass = 0; pass < 2; ++pass)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (a != b) common[a] = at_common_times(common[a], common[b]);
  ReferenceVerification v;
  double rms[3], peak[3];
  std::vector<const ProfileRow*> rows_at[3];
  for (int k = 0; k < 3; ++k) {
    v.levels[k] = sorted[k]->level;
    v.element_sizes[k] = sorted[k]->element_size;
    const auto rows = rows_of_tool(common[k], tool);
    if (rows.size() < 2)
      throw std::invalid_argument("reference verification: the three finest levels (L" + std::to_string(sorted[0]->level) + ", L" +
                                  std::to_string(sorted[1]->level) + ", L" + std::to_string(sorted[2]->level) + ") share " +
                                  std::to_string(rows.size()) + " sample(s) of tool " + tool + ", fewer than 2");
    v.samples = rows.size();
    rows_at[k] = rows;
  }
  // Time weights of the common samples (profile_metrics.hpp): the same times at every level.
  std::vector<double> times;
  for (const ProfileRow* r : rows_at[0]) times.push_back(r->t);
  const std::vector<double> w = sample_time_weights(times);
  double total = 0.0;
  for (double x : w) total += x;
  for (int k = 0; k < 3; ++k) {
    double sum = 0.0;
    peak[k] = 0.0;
    for (std::size_t i = 0; i < rows_at[k].size(); ++i) {
      sum += w[i] * rows_at[k][i]->force.squaredNorm();
      peak[k] = std::max(peak[k], rows_at[k][i]->force.norm());
    }
    rms[k] = std::sqrt(sum / total);
  }
  v.rms_force = rms[0];
  v.peak_force = peak[0];
  v.rms = grid_convergence({v.element_sizes[0], v.element_sizes[1], v.element_sizes[2], rms[0], rms[1], rms[2]});
  v.peak = grid_convergence({v.element_sizes[0], v.element_sizes[1], v.element_sizes[2], peak[0], peak[1], peak[2]});
  // The RMS over the common samples of the force differences between successive levels.
  const auto rms_difference = [&](int a, int b) {
    double sum = 0.0;
    for (std::size_t i = 0; i < rows_at[a].size(); ++i) sum += w[i] * (rows_at[a][i]->force - rows_at[b][i]->force).squaredNorm();
    return std::sqrt(sum / total);
  };
  v.profile = difference_convergence(v.element_sizes[0], v.element_sizes[1], v.element_sizes[2], rms_difference(0, 1),
                                     rms_difference(1, 2), formal_order);
  return v;
}

std::string SamplingVerification::summary() const {
  char text[320];
  std::snprintf(text, sizeof text,
                "sampling uncertainty %.2g %% of the peak (the run at the study's load increment, %zu samples, against half of "
                "it, %zu samples: %.3g N RMS at %zu common times, RMS |F| moves %.3g N, peak |F| %.3g N; largest at t = %.4g s, %s: "
                "%.3g N against %.3g N)",
                peak_force > 0.0 ? 100.0 * uncertainty() / peak_force : 0.0, loads_whole, loads_half, rms_difference, samples, rms_shift,
                peak_difference, largest_difference_time, std::string(to_string(largest_difference_mode)).c_str(), largest_difference_force,
                largest_difference_force_half);
  return text;
}

SamplingVerification verify_sampling(const ForceProfile& whole, const ForceProfile& half, const std::string& tool) {
  const auto all_whole = rows_of_tool(whole, tool), all_half = rows_of_tool(half, tool);
  // rows_of_tool points into its profile: the common profiles are kept while their rows are read.
  const ForceProfile common_whole = at_common_times(whole, half), common_half = at_common_times(half, whole);
  const auto a = rows_of_tool(common_whole, tool);
  const auto b = rows_of_tool(common_half, tool);
  if (a.size() < 2 || a.size() != b.size())
    throw std::invalid_argument("sampling verification: the runs at the study's load increment and at half of it share " +
                                std::to_string(std::min(a.size(), b.size())) + " output time(s) of tool " + tool + ", fewer than 2");
  SamplingVerification v;
  v.samples = a.size();
  v.loads_whole = all_whole.size();
  v.loads_half = all_half.size();
  std::vector<double> times;
  for (const ProfileRow* r : a) times.push_back(r->t);
  const std::vector<double> w = sample_time_weights(times);
  double sum = 0.0, total = 0.0, largest = -1.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double d = (a[i]->force - b[i]->force).norm();
    sum += w[i] * d * d;
    total += w[i];
    if (d > largest) {
      largest = d;
      v.largest_difference_time = a[i]->t;
      v.largest_difference_mode = a[i]->mode;
      v.largest_difference_force = a[i]->force.norm();
      v.largest_difference_force_half = b[i]->force.norm();
    }
  }
  v.rms_difference = std::sqrt(sum / total);
  // The time-weighted RMS |F| of each run over its own samples.
  const auto rms_over_own_samples = [](const std::vector<const ProfileRow*>& rows) {
    std::vector<double> t;
    for (const ProfileRow* r : rows) t.push_back(r->t);
    const std::vector<double> weights = sample_time_weights(t);
    double s = 0.0, total_weight = 0.0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
      s += weights[i] * rows[i]->force.squaredNorm();
      total_weight += weights[i];
    }
    return total_weight > 0.0 ? std::sqrt(s / total_weight) : 0.0;
  };
  v.rms_shift = std::abs(rms_over_own_samples(all_half) - rms_over_own_samples(all_whole));
  double peak_half = 0.0;
  for (const ProfileRow* r : all_whole) v.peak_force = std::max(v.peak_force, r->force.norm());
  for (const ProfileRow* r : all_half) peak_half = std::max(peak_half, r->force.norm());
  v.peak_difference = std::abs(peak_half - v.peak_force);
  return v;
}

std::optional<double> combined_uncertainty(const std::optional<ReferenceVerification>& space,
                                           const std::optional<SamplingVerification>& time) {
  const std::optional<double> u_space = space ? space->profile_uncertainty() : std::nullopt;
  if (!time) return u_space;
  const double u_time = time->uncertainty();
  if (!u_space) return u_time;
  return std::sqrt(*u_space * *u_space + u_time * u_time);
}

ReferenceBand reference_band(const std::vector<ReferenceLevel>& levels, const std::optional<ReferenceVerification>& verification,
                             const std::string& tool, const Eigen::Vector3d& direction) {
  ReferenceBand band;
  if (levels.empty()) return band;
  const auto sorted = by_element_size(levels);
  const auto resisting = [&](const ProfileRow* r) { return -r->force.dot(direction); };
  const auto fine = rows_of_tool(sorted[0]->profile, tool);
  std::vector<std::vector<const ProfileRow*>> others;
  for (std::size_t k = 1; k < sorted.size(); ++k) others.push_back(rows_of_tool(sorted[k]->profile, tool));
  band.from_gci = verification && verification->profile.usable() && sorted.size() >= 2;
  for (const ProfileRow* r : fine) {
    const double f1 = resisting(r);
    const ProfileRow* medium = others.empty() ? nullptr : at_time(others.front(), r->t);
    if (band.from_gci && medium) {
      const double u = gci_band_half_width({f1}, {resisting(medium)}, sorted[1]->element_size / sorted[0]->element_size,
                                           *verification->profile.order_used)
                           .front();
      band.low.push_back(f1 - u);
      band.high.push_back(f1 + u);
      continue;
    }
    double low = f1, high = f1;
    for (const auto& rows : others)
      if (const ProfileRow* o = at_time(rows, r->t)) {
        low = std::min(low, resisting(o));
        high = std::max(high, resisting(o));
      }
    band.low.push_back(low);
    band.high.push_back(high);
  }
  return band;
}

} // namespace kerf
