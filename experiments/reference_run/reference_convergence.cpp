#include "experiments/reference_run/reference_convergence.hpp"

#include "meshes/atomic_file.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace kerf {

namespace {

std::string format(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

} // namespace

ConvergenceStudy run_reference_convergence(const Scene& scene, const TetMesh& mesh, const ReferenceRunSettings& settings,
                                           int levels, const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  if (levels < 3)
    throw std::invalid_argument("reference convergence: at least 3 levels are needed for an observed order, got " +
                                std::to_string(levels));
  ConvergenceStudy study;
  for (int k = 0; k < levels; ++k) {
    ReferenceRunSettings s = settings;
    s.refinements = settings.refinements + k;
    const fs::path level_dir = dir / ("refine_" + std::to_string(s.refinements));
    const auto begin = std::chrono::steady_clock::now();
    ConvergenceLevel level;
    level.refinements = s.refinements;
    level.profile = run_reference(scene, mesh, s, level_dir).profile;
    level.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    std::ifstream in(level_dir / "manifest.json");
    const nlohmann::json manifest = nlohmann::json::parse(in);
    level.dofs = manifest.at("solver").at("dofs").get<std::size_t>();
    if (!manifest.at("stopped").is_null())
      throw std::runtime_error("reference convergence: the run at " + std::to_string(s.refinements) +
                               " refinements stopped: " + manifest.at("stopped").get<std::string>());
    study.levels.push_back(std::move(level));
  }
  const std::size_t n = study.levels.front().profile.rows.size();
  for (const ConvergenceLevel& l : study.levels) {
    if (l.profile.rows.size() != n)
      throw std::runtime_error("reference convergence: the levels solved different numbers of samples");
    double peak = 0.0;
    for (const ProfileRow& r : l.profile.rows) peak = std::max(peak, r.force.norm());
    study.peak_force.push_back(peak);
  }
  // D_k = max_t |F_{k+1}(t) − F_k(t)|
  for (std::size_t k = 0; k + 1 < study.levels.size(); ++k) {
    double d = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      d = std::max(d, (study.levels[k + 1].profile.rows[i].force - study.levels[k].profile.rows[i].force).norm());
    study.max_difference.push_back(d);
  }
  // p_k = ln(D_k / D_{k+1}) / ln 2 (refinement ratio 2); NaN when a difference is zero
  for (std::size_t k = 0; k + 1 < study.max_difference.size(); ++k) {
    const double a = study.max_difference[k], b = study.max_difference[k + 1];
    study.observed_order.push_back(a > 0.0 && b > 0.0 ? std::log(a / b) / std::log(2.0)
                                                      : std::numeric_limits<double>::quiet_NaN());
  }

  fs::create_directories(dir);
  write_atomically(dir / "convergence.csv", [&](const fs::path& tmp) {
    std::ofstream out(tmp);
    if (!out) throw std::runtime_error("reference convergence: cannot write " + tmp.string());
    out << "t,px,py,pz";
    for (const ConvergenceLevel& l : study.levels) out << ",F_refine_" << l.refinements;
    out << "\n";
    out.precision(17);
    for (std::size_t i = 0; i < n; ++i) {
      const ProfileRow& r = study.levels.front().profile.rows[i];
      out << r.t << "," << r.position.x() << "," << r.position.y() << "," << r.position.z();
      for (const ConvergenceLevel& l : study.levels) out << "," << l.profile.rows[i].force.norm();
      out << "\n";
    }
    out.flush();
    if (!out) throw std::runtime_error("reference convergence: writing " + tmp.string() + " failed");
  });
  const std::string md = convergence_markdown(scene, study);
  write_atomically(dir / "convergence.md", [&](const fs::path& tmp) {
    std::ofstream out(tmp);
    out << md;
    out.flush();
    if (!out) throw std::runtime_error("reference convergence: writing " + tmp.string() + " failed");
  });
  return study;
}

std::string convergence_markdown(const Scene& scene, const ConvergenceStudy& study) {
  std::ostringstream md;
  md << "Convergence of `" << scene.name << "` (" << study.levels.size()
     << " levels, refinement ratio 2):\n\n| refinements | DOFs | peak abs(F) (N) | wall (s) | "
        "D = max_t abs(F_next − F) (N) | observed order p |\n|---|---|---|---|---|---|\n";
  for (std::size_t k = 0; k < study.levels.size(); ++k) {
    const ConvergenceLevel& l = study.levels[k];
    md << "| " << l.refinements << " | " << l.dofs << " | " << format("%.5g", study.peak_force[k]) << " | "
       << format("%.1f", l.wall_s) << " | "
       << (k < study.max_difference.size() ? format("%.4g", study.max_difference[k]) : std::string()) << " | "
       << (k < study.observed_order.size() ? format("%.2f", study.observed_order[k]) : std::string()) << " |\n";
  }
  md << "\n| t (s) | tool z (mm) |";
  for (const ConvergenceLevel& l : study.levels) md << " abs(F), refine " << l.refinements << " (N) |";
  md << "\n|---|---|";
  for (std::size_t k = 0; k < study.levels.size(); ++k) md << "---|";
  md << "\n";
  for (std::size_t i = 0; i < study.levels.front().profile.rows.size(); ++i) {
    const ProfileRow& r = study.levels.front().profile.rows[i];
    md << "| " << format("%.3f", r.t) << " | " << format("%.3f", r.position.z() * 1e3) << " |";
    for (const ConvergenceLevel& l : study.levels) md << " " << format("%.5g", l.profile.rows[i].force.norm()) << " |";
    md << "\n";
  }
  return md.str();
}

} // namespace kerf
