#include "experiments/study/stability_sweep.hpp"

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "formats/scene/scene_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

namespace kerf {

std::string_view to_string(StabilityClass c) {
  switch (c) {
  case StabilityClass::bounded: return "bounded";
  case StabilityClass::oscillating: return "oscillating";
  case StabilityClass::diverged: return "diverged";
  case StabilityClass::non_finite: return "NaN";
  case StabilityClass::refused: return "refused";
  }
  return "?";
}

std::vector<StabilityAxis> default_stability_axes() {
  return {{"rate", {0.25, 0.5, 2.0, 4.0, 16.0}},
          {"stiffness", {1e-3, 1e-2, 1e-1, 10.0, 1e2, 1e3}},
          {"toughness", {1e-2, 1e-1, 10.0, 1e2}},
          {"speed", {0.1, 10.0, 100.0}},
          {"poisson", {0.3, 0.45, 0.49, 0.499}},
          {"element_size", {0.5, 2.0}}};
}

Scene scaled_scene(const Scene& nominal, const std::string& axis, double value) {
  Scene s = nominal;
  auto each_material = [&](auto&& f) {
    f(s.material);
    for (Material& m : s.layers) f(m);
  };
  if (axis == "rate") {
    for (Tool& t : s.tools) t.trajectory.rate *= value;
  } else if (axis == "speed") {
    for (Tool& t : s.tools)
      for (TrajectorySegment& seg : t.trajectory.segments)
        if (seg.kind == TrajectorySegment::Kind::move) seg.speed *= value;
  } else if (axis == "stiffness") {
    each_material([&](Material& m) { m.youngs_modulus *= value; });
    if (s.fracture) {
      s.fracture->rupture_force_per_length *= value;
      s.fracture->lateral_stiffness *= value;
      s.fracture->presliding_stiffness *= value;
    }
    if (s.voxel) s.voxel->elastic_coefficient *= value;
  } else if (axis == "toughness") {
    each_material([&](Material& m) { m.fracture_toughness *= value; });
  } else if (axis == "poisson") {
    each_material([&](Material& m) { m.poisson_ratio = value; });
  } else if (axis == "element_size") {
    s.geometry.element_size *= value;
  } else {
    throw std::invalid_argument("stability sweep: unknown axis \"" + axis + "\"");
  }
  return s;
}

namespace {

struct RunOutcome {
  ForceProfile profile;
  std::string refusal;
};

RunOutcome run_once(const Scene& scene, const std::string& model, const TetMesh* mesh) {
  RunOutcome out;
  try {
    const TetMesh own = mesh ? TetMesh{} : scene_mesh(scene);
    BuiltModel built = make_model(model, scene, mesh ? *mesh : own);
    std::vector<std::string> names;
    for (const Tool& t : scene.tools) names.push_back(t.name);
    out.profile = run_model(*built.model, names, sample_scene_trajectories(scene));
  } catch (const std::exception& e) {
    out.refusal = e.what();
  }
  return out;
}

double peak_force(const ForceProfile& p, bool& finite) {
  double peak = 0.0;
  finite = true;
  for (const ProfileRow& r : p.rows) {
    if (!r.force.allFinite()) finite = false;
    else peak = std::max(peak, r.force.norm());
  }
  return peak;
}

/// Fraction of samples where the increment of |f| of a tool changes sign while both increments
/// are significant (above 1e-6 of the scale): a sustained numerical oscillation shows as about
/// half the samples; a physical profile (load, rupture, unload) as a handful.
double reversal_fraction(const ForceProfile& p, double scale) {
  std::size_t reversals = 0, counted = 0;
  std::map<std::string, std::pair<double, double>> last; // tool -> (|f| previous, previous increment)
  for (const ProfileRow& r : p.rows) {
    const double f = r.force.norm();
    auto it = last.find(r.tool);
    if (it == last.end()) {
      last[r.tool] = {f, 0.0};
      continue;
    }
    const double increment = f - it->second.first;
    const double previous = it->second.second;
    if (std::abs(increment) > 1e-6 * scale && std::abs(previous) > 1e-6 * scale && (increment > 0) != (previous > 0))
      ++reversals;
    ++counted;
    it->second = {f, increment};
  }
  return counted ? static_cast<double>(reversals) / static_cast<double>(counted) : 0.0;
}

} // namespace

std::vector<StabilityPoint> stability_sweep(const Scene& nominal, const std::string& model,
                                            const StabilitySettings& settings) {
  require_model_for_scene(model, nominal);
  const TetMesh mesh = scene_mesh(nominal);
  const RunOutcome base = run_once(nominal, model, &mesh);
  if (!base.refusal.empty()) throw std::runtime_error("stability sweep: the nominal run failed: " + base.refusal);
  bool finite = true;
  const double nominal_peak = peak_force(base.profile, finite);
  if (!finite || !(nominal_peak > 0.0))
    throw std::runtime_error("stability sweep: the nominal run has no finite, non-zero force to scale by");

  std::vector<StabilityPoint> points;
  for (const StabilityAxis& axis : settings.axes)
    for (double value : axis.values) {
      StabilityPoint p;
      p.axis = axis.name;
      p.value = value;
      const Scene scene = scaled_scene(nominal, axis.name, value);
      // Forces scale with stiffness and toughness; the other axes leave the physical scale.
      const bool scales = axis.name == "stiffness" || axis.name == "toughness";
      p.expected_scale = nominal_peak * (scales ? std::max(1.0, value) : 1.0);
      const RunOutcome run = run_once(scene, model, axis.name == "element_size" ? nullptr : &mesh);
      if (!run.refusal.empty()) {
        p.outcome = StabilityClass::refused;
        p.note = run.refusal;
      } else {
        p.peak_force = peak_force(run.profile, finite);
        p.reversal_fraction = reversal_fraction(run.profile, p.expected_scale);
        if (!finite) p.outcome = StabilityClass::non_finite;
        else if (p.peak_force > settings.divergence_factor * p.expected_scale) p.outcome = StabilityClass::diverged;
        else if (p.reversal_fraction > settings.oscillation_fraction) p.outcome = StabilityClass::oscillating;
      }
      points.push_back(std::move(p));
    }
  return points;
}

std::string stability_edges(const std::vector<StabilityPoint>& points) {
  const auto shown = [](const std::string& axis, double v) {
    char b[32];
    std::snprintf(b, sizeof b, axis == "poisson" ? "ν = %g" : "×%g", v);
    return std::string(b);
  };
  std::vector<std::string> axes;
  for (const StabilityPoint& p : points)
    if (std::find(axes.begin(), axes.end(), p.axis) == axes.end()) axes.push_back(p.axis);
  std::string out;
  for (const std::string& axis : axes) {
    std::vector<const StabilityPoint*> mine;
    for (const StabilityPoint& p : points)
      if (p.axis == axis) mine.push_back(&p);
    std::sort(mine.begin(), mine.end(), [](auto a, auto b) { return a->value < b->value; });
    std::vector<const StabilityPoint*> bounded, other;
    for (const StabilityPoint* p : mine) (p->outcome == StabilityClass::bounded ? bounded : other).push_back(p);
    out += "- " + axis + " " + shown(axis, mine.front()->value) + " … " + shown(axis, mine.back()->value) + ": ";
    if (other.empty()) {
      out += "bounded at all " + std::to_string(mine.size()) + "\n";
      continue;
    }
    out += bounded.empty() ? "bounded at none"
                           : "bounded at " + (bounded.size() == 1 ? shown(axis, bounded.front()->value)
                                                                  : shown(axis, bounded.front()->value) + " … " +
                                                                        shown(axis, bounded.back()->value)) +
                                 " (" + std::to_string(bounded.size()) + " of " + std::to_string(mine.size()) + ")";
    for (const StabilityPoint* p : other) {
      char detail[96] = "";
      if (p->outcome == StabilityClass::oscillating)
        std::snprintf(detail, sizeof detail, " (%.0f %% reversing)", 100.0 * p->reversal_fraction);
      else if (p->outcome == StabilityClass::diverged)
        std::snprintf(detail, sizeof detail, " (peak %.3g N, %.0f× the scale)", p->peak_force, p->peak_force / p->expected_scale);
      out += "; " + shown(axis, p->value) + " " + std::string(to_string(p->outcome)) + detail;
      if (p->outcome == StabilityClass::refused) {
        std::string why = p->note.substr(0, 140);
        for (char& c : why)
          if (c == '\n' || c == '|') c = ' ';
        out += " (\"" + why + (p->note.size() > 140 ? "…" : "") + "\")";
      }
    }
    out += "\n";
  }
  return out;
}

} // namespace kerf
