#include "formats/profile/profile_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <stdexcept>
#include <vector>

namespace kerf {

namespace {

std::optional<double> rupture_travel(const std::vector<const ProfileRow*>& rows) {
  for (const ProfileRow* r : rows)
    if (r->mode == InteractionMode::rupture) return (r->position - rows.front()->position).norm();
  return std::nullopt;
}

} // namespace

std::vector<double> sample_time_weights(const std::vector<double>& times) {
  const std::size_t n = times.size();
  if (n == 1) return {1.0};
  std::vector<double> w(n, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const double before = k > 0 ? times[k] - times[k - 1] : 0.0;
    const double after = k + 1 < n ? times[k + 1] - times[k] : 0.0;
    w[k] = 0.5 * (before + after);
  }
  return w;
}

const PhaseError* ProfileMetrics::dominant_phase() const {
  const PhaseError* out = nullptr;
  for (const PhaseError& p : phases)
    if (p.error_share > 0.0 && (!out || p.error_share > out->error_share)) out = &p;
  return out;
}

ProfileMetrics compare_profiles(const ForceProfile& model, const ForceProfile& reference, const std::string& tool,
                                const std::optional<SteadyCuttingExpectation>& cutting) {
  const auto m = rows_of_tool(model, tool);
  const auto r = rows_of_tool(reference, tool);
  if (m.empty() || m.size() != r.size())
    throw std::invalid_argument("compare profiles: tool " + tool + " has " + std::to_string(m.size()) +
                                " model samples and " + std::to_string(r.size()) + " reference samples");
  std::vector<double> times;
  for (std::size_t k = 0; k < m.size(); ++k) {
    if (std::abs(m[k]->t - r[k]->t) > 1e-9)
      throw std::invalid_argument("compare profiles: sample " + std::to_string(k) + " is at t = " +
                                  std::to_string(m[k]->t) + " s in the model and " + std::to_string(r[k]->t) +
                                  " s in the reference");
    times.push_back(r[k]->t);
  }
  const std::vector<double> w = sample_time_weights(times);
  ProfileMetrics out;
  out.samples = m.size();
  double sum_squared = 0.0, total_weight = 0.0, same_mode = 0.0, peak_model = 0.0, peak_reference = 0.0;
  // Per phase of the reference: Σ w and Σ w |Δf|², in the order the phases first occur.
  std::vector<std::pair<InteractionMode, std::pair<double, double>>> phase_sums;
  for (std::size_t k = 0; k < m.size(); ++k) {
    const double e2 = w[k] * (m[k]->force - r[k]->force).squaredNorm();
    sum_squared += e2;
    total_weight += w[k];
    peak_model = std::max(peak_model, m[k]->force.norm());
    peak_reference = std::max(peak_reference, r[k]->force.norm());
    if (m[k]->mode == r[k]->mode) same_mode += w[k];
    auto phase = std::find_if(phase_sums.begin(), phase_sums.end(), [&](const auto& p) { return p.first == r[k]->mode; });
    if (phase == phase_sums.end()) phase = phase_sums.insert(phase_sums.end(), {r[k]->mode, {0.0, 0.0}});
    phase->second.first += w[k];
    phase->second.second += e2;
  }
  if (!(peak_reference > 0.0)) throw std::invalid_argument("not scored: the reference force is zero on every compared sample");
  if (!(total_weight > 0.0)) throw std::invalid_argument("not scored: the compared samples span no time");
  out.normalised_rms_force_error = std::sqrt(sum_squared / total_weight) / peak_reference;
  out.peak_force_error = (peak_model - peak_reference) / peak_reference;
  out.mode_agreement = same_mode / total_weight;
  out.reference_peak_force = peak_reference;
  for (const auto& [mode, sums] : phase_sums) {
    PhaseError p;
    p.mode = mode;
    p.time_fraction = sums.first / total_weight;
    p.normalised_rms_force_error = sums.first > 0.0 ? std::sqrt(sums.second / sums.first) / peak_reference : 0.0;
    p.error_share = sum_squared > 0.0 ? sums.second / sum_squared : 0.0;
    out.phases.push_back(p);
  }

  const auto rm = rupture_travel(m), rr = rupture_travel(r);
  if (rm && rr) out.rupture_displacement_error = *rm - *rr;

  const std::size_t last = m.size() - 1;
  const double work_model = tool_work(model, tool, 0, last), work_reference = tool_work(reference, tool, 0, last);
  if (!(std::abs(work_reference) > 0.0)) throw std::invalid_argument("not scored: the reference does no work on the compared samples");
  out.work_error = (work_model - work_reference) / std::abs(work_reference);

  if (cutting && cutting->force > 0.0) {
    double sum = 0.0;
    std::size_t count = 0;
    // The body pushes the blade back against its advance: the resisting force is -f . d.
    for (const ProfileRow* row : m)
      if (row->mode == InteractionMode::cutting) {
        sum += -row->force.dot(cutting->cutting_direction);
        ++count;
      }
    if (count > 0) out.steady_cutting_force_error = (sum / static_cast<double>(count) - cutting->force) / cutting->force;
  }
  return out;
}

ForceProfile at_common_times(const ForceProfile& a, const ForceProfile& b) {
  std::map<std::string, std::vector<double>> times;
  for (const ProfileRow& r : b.rows) times[r.tool].push_back(r.t);
  for (auto& [tool, t] : times) std::sort(t.begin(), t.end());
  ForceProfile out;
  for (const ProfileRow& r : a.rows) {
    const auto it = times.find(r.tool);
    if (it == times.end()) continue;
    const auto lo = std::lower_bound(it->second.begin(), it->second.end(), r.t - 1e-9);
    if (lo != it->second.end() && *lo <= r.t + 1e-9) out.rows.push_back(r);
  }
  return out;
}

} // namespace kerf
