#include "experiments/study/profile_metrics.hpp"

#include <cmath>
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

ProfileMetrics compare_profiles(const ForceProfile& model, const ForceProfile& reference, const std::string& tool,
                                const std::optional<SteadyCuttingExpectation>& cutting) {
  const auto m = rows_of_tool(model, tool);
  const auto r = rows_of_tool(reference, tool);
  if (m.empty() || m.size() != r.size())
    throw std::invalid_argument("compare profiles: tool " + tool + " has " + std::to_string(m.size()) +
                                " model samples and " + std::to_string(r.size()) + " reference samples");
  ProfileMetrics out;
  out.samples = m.size();
  double sum_squared = 0.0, peak_model = 0.0, peak_reference = 0.0;
  std::size_t same_mode = 0;
  for (std::size_t k = 0; k < m.size(); ++k) {
    if (std::abs(m[k]->t - r[k]->t) > 1e-9)
      throw std::invalid_argument("compare profiles: sample " + std::to_string(k) + " is at t = " +
                                  std::to_string(m[k]->t) + " s in the model and " + std::to_string(r[k]->t) +
                                  " s in the reference");
    sum_squared += (m[k]->force - r[k]->force).squaredNorm();
    peak_model = std::max(peak_model, m[k]->force.norm());
    peak_reference = std::max(peak_reference, r[k]->force.norm());
    if (m[k]->mode == r[k]->mode) ++same_mode;
  }
  if (!(peak_reference > 0.0)) throw std::invalid_argument("not scored: the reference force is zero on every compared sample");
  const auto n = static_cast<double>(m.size());
  out.normalised_rms_force_error = std::sqrt(sum_squared / n) / peak_reference;
  out.peak_force_error = (peak_model - peak_reference) / peak_reference;
  out.mode_agreement = static_cast<double>(same_mode) / n;
  out.reference_peak_force = peak_reference;

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

} // namespace kerf
