#include "experiments/calibration/calibration.hpp"

#include "experiments/models/run_model.hpp"
#include "formats/profile/profile_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace kerf {

CalibratedParameters scene_parameters(const std::string& model, const Scene& scene) {
  const auto free = free_parameters(model);
  if (free.empty()) throw std::invalid_argument("calibrate: model \"" + model + "\" has no calibrated parameters (fracture, springs, voxel have)");
  if (model == "fracture" && !scene.fracture)
    throw ModelMismatch("calibrate: scene " + scene.name + " has no [models.fracture] section to start from");
  if (model == "voxel" && !scene.voxel)
    throw ModelMismatch("calibrate: scene " + scene.name + " has no [models.voxel] section to start from");
  CalibratedParameters p;
  p.model = model;
  for (const FreeParameter& f : free) p.values.push_back(f.get(scene));
  if (model == "fracture") {
    p.deformation_1_exponent = scene.fracture->deformation_1_exponent;
    p.deformation_2_exponent = scene.fracture->deformation_2_exponent;
  }
  return p;
}

Scene with_parameters(const Scene& scene, const CalibratedParameters& p) {
  Scene s = scene;
  const auto free = free_parameters(p.model);
  if (free.size() != p.values.size())
    throw std::invalid_argument("calibrate: " + std::to_string(p.values.size()) + " values for the " +
                                std::to_string(free.size()) + " parameters of model " + p.model);
  for (std::size_t k = 0; k < free.size(); ++k) free[k].set(s, p.values[k]);
  if (p.deformation_1_exponent) s.fracture->deformation_1_exponent = *p.deformation_1_exponent;
  if (p.deformation_2_exponent) s.fracture->deformation_2_exponent = *p.deformation_2_exponent;
  return s;
}

double profile_error(const std::string& model, const Scene& scene, const TetMesh& mesh, const ForceProfile& target) {
  BuiltModel built = make_model(model, scene, mesh);
  std::vector<std::string> names;
  for (const Tool& t : scene.tools) names.push_back(t.name);
  const ForceProfile profile = run_model(*built.model, names, sample_scene_trajectories(scene));
  const ForceProfile m = at_common_times(profile, target);
  const ForceProfile r = at_common_times(target, profile);
  double sum = 0.0;
  int tools = 0;
  for (const std::string& tool : names) {
    bool present = false;
    for (const ProfileRow& row : r.rows) present = present || row.tool == tool;
    if (!present) continue;
    sum += compare_profiles(m, r, tool).normalised_rms_force_error;
    ++tools;
  }
  if (tools == 0) throw std::invalid_argument("calibrate: the target shares no sample with the trajectory of scene " + scene.name);
  return sum / tools;
}

namespace {

/// One simplex search over ln(p / p0) with the exponents of `start` held.
CalibrationResult search(const std::string& model, const CalibrationTarget& target, const TetMesh& mesh,
                         const CalibratedParameters& start, const NelderMeadSettings& simplex) {
  CalibrationResult r;
  r.initial = start;
  const auto n = static_cast<Eigen::Index>(start.values.size());
  const auto at = [&](const Eigen::VectorXd& y) {
    CalibratedParameters p = start;
    // p_k = p0_k exp(y_k): the search runs over logarithms, so every trial value is positive.
    for (Eigen::Index k = 0; k < n; ++k) p.values[static_cast<std::size_t>(k)] *= std::exp(y[k]);
    return p;
  };
  const auto objective = [&](const Eigen::VectorXd& y) {
    try {
      return profile_error(model, with_parameters(target.scene, at(y)), mesh, target.profile);
    } catch (const ModelMismatch&) {
      throw;
    } catch (const std::exception&) {
      return std::numeric_limits<double>::infinity(); // a model that refuses these values: move away
    }
  };
  const NelderMeadResult nm = nelder_mead(objective, Eigen::VectorXd::Zero(n), simplex);
  r.fitted = at(nm.x);
  r.fitted_error = nm.value;
  r.evaluations = nm.evaluations;
  r.converged = nm.converged;
  return r;
}

} // namespace

CalibrationResult calibrate(const std::string& model, const CalibrationTarget& target, const TetMesh& mesh,
                            const CalibrationSettings& settings) {
  const CalibratedParameters start = scene_parameters(model, target.scene);
  // The starting error (also checks that the target is usable: it throws if it carries no force).
  const double initial_error = profile_error(model, target.scene, mesh, target.profile);

  std::vector<CalibratedParameters> starts{start};
  if (model == "fracture" && settings.fit_exponents) {
    starts.clear();
    for (int i = 1; i <= 3; ++i)
      for (int j = 1; j <= 3; ++j) {
        CalibratedParameters s = start;
        s.deformation_1_exponent = i;
        s.deformation_2_exponent = j;
        starts.push_back(s);
      }
  }
  int evaluations = 1;
  NelderMeadSettings screening = settings.simplex;
  if (starts.size() > 1) screening.max_evaluations = std::min(settings.simplex.max_evaluations, settings.screening_evaluations);
  std::vector<CalibrationResult> screened;
  for (const CalibratedParameters& s : starts) {
    screened.push_back(search(model, target, mesh, s, screening));
    evaluations += screened.back().evaluations;
  }
  std::sort(screened.begin(), screened.end(), [](const auto& a, const auto& b) { return a.fitted_error < b.fitted_error; });
  if (starts.size() > 1) // refine the best pairs from where their screening stopped
    for (std::size_t k = 0; k < std::min<std::size_t>(screened.size(), static_cast<std::size_t>(std::max(1, settings.refined_pairs))); ++k) {
      if (screened[k].converged) continue;
      CalibrationResult r = search(model, target, mesh, screened[k].fitted, settings.simplex);
      evaluations += r.evaluations;
      if (r.fitted_error <= screened[k].fitted_error) screened[k] = std::move(r);
    }
  CalibrationResult best = *std::min_element(screened.begin(), screened.end(),
                                             [](const auto& a, const auto& b) { return a.fitted_error < b.fitted_error; });
  if (!std::isfinite(best.fitted_error))
    throw std::runtime_error("calibrate: model " + model + " ran on no trial parameters of scene " + target.scene.name);
  best.initial = start;
  best.initial_error = initial_error;
  best.evaluations = evaluations;
  return best;
}

std::string parameter_file_text(const CalibratedParameters& p, const std::string& comment) {
  std::ostringstream out;
  std::istringstream lines(comment);
  for (std::string line; std::getline(lines, line);) out << (line.empty() ? "#" : "# " + line) << '\n';
  out << "\n[models." << p.model << "]\n";
  const auto free = free_parameters(p.model);
  for (std::size_t k = 0; k < free.size(); ++k) {
    char number[64];
    std::snprintf(number, sizeof number, "%.9g", p.values[k] / free[k].unit_value);
    out << free[k].key << " = ";
    if (free[k].unit.empty()) out << number;
    else out << '"' << number << ' ' << free[k].unit << '"';
    out << "   # " << free[k].symbol << ": " << free[k].meaning << '\n';
  }
  if (p.deformation_1_exponent)
    out << "deformation_1_exponent = " << *p.deformation_1_exponent << "   # i: f1 = f_r (δ/δ_r)^i (paper 001 §6)\n";
  if (p.deformation_2_exponent)
    out << "deformation_2_exponent = " << *p.deformation_2_exponent << "   # j: f2 = J_c (δ/δ_c)^j (paper 001 §6)\n";
  return out.str();
}

} // namespace kerf
