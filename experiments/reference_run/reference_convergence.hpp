#pragma once
// Mesh convergence of the reference (docs/reference.md): the same scene run at successive global
// refinements of its mesh (each halves the element size h; nested meshes, so every level solves
// the same boundary-value problem), the force–displacement curves compared sample by sample, and
// the observed order of convergence
//   p_k = ln(D_k / D_{k+1}) / ln 2,   D_k = max over samples |F_{k+1}(t) − F_k(t)|
// (Roache 1998, "Verification and Validation in Computational Science and Engineering", §5.4:
// the observed order from three systematically refined grids, refinement ratio 2).

#include "experiments/reference_run/reference_run.hpp"

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace kerf {

/// One refinement level of the study.
struct ConvergenceLevel {
  int refinements = 0;
  std::size_t dofs = 0;
  ForceProfile profile;
  double wall_s = 0.0; ///< wall time of the level's run [s]
};

/// The study: levels in refinement order, their curve differences and observed orders.
struct ConvergenceStudy {
  std::vector<ConvergenceLevel> levels;
  std::vector<double> max_difference; ///< D_k = max_t |F_{k+1}(t) − F_k(t)| [N], one per pair of levels
  std::vector<double> observed_order; ///< p_k = log2(D_k / D_{k+1}), one per triple of levels
  std::vector<double> peak_force;     ///< max_t |F_k(t)| per level [N]
};

/// Runs the reference on `scene` at refinements settings.refinements + k, k = 0 .. levels − 1,
/// into dir/refine_<r>, each solving the same samples, and compares the profiles (see file
/// comment). Writes dir/convergence.csv (t, tool position, |F| per level) and dir/convergence.md
/// (the tables for docs). Throws std::invalid_argument for fewer than 3 levels, and
/// std::runtime_error if a level stopped before its last sample (curves of different length).
ConvergenceStudy run_reference_convergence(const Scene& scene, const TetMesh& mesh, const ReferenceRunSettings& settings,
                                           int levels, const std::filesystem::path& dir);

/// The markdown written to dir/convergence.md: per level refinements, DOFs, peak |F|, wall time,
/// D_k and p_k, then the curves |F_k(t)|.
std::string convergence_markdown(const Scene& scene, const ConvergenceStudy& study);

} // namespace kerf
