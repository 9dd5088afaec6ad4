#pragma once
// The reference cache of a study: cached by the hash of the scene and the solver settings, so a
// re-run reuses it. A reference solve is identified by every input that changes its
// numbers: the scene (its file, the geometry it meshes, the materials, the sampled trajectory at
// the solved samples — a trajectory scaled or replayed in memory is not in the file) and the
// solver settings (FE degree, mesh level, linear solver and its tolerances, Newton tolerances,
// contact penalty, load-path cut-backs, cohesive fracture on/off, the number of MPI processes the
// mesh is distributed over). Any change of one of them misses the cache; nothing else does.
//
// The reference's code enters through its version (reference/solver_version.hpp), a number the
// reference bumps whenever its numbers change: a profile cached by another version has another
// key, so it is recomputed, never read.

#include "experiments/reference_run/reference_run.hpp"
#include "formats/scene/scene.hpp"
#include "experiments/study/study_spec.hpp"
#include "reference/solver_version.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace kerf {

/// The load increment of a study's reference solve: the study's own, or half of it (the second
/// solve of the finest level that verifies the reference in time, StudyReferenceSpec::time_verification).
enum class LoadIncrement { whole, half };

/// The settings a study's reference solve of `scene` at mesh level `level` runs with: `spec`'s
/// degree for the scene (StudyReferenceSpec::degree_of its file's stem and its element_degree),
/// linear solver and fracture mode, the solved `sample_indices`, adaptive sampling with `spec`'s
/// force change and a least travel of 1/40 of the scene's own element size (1/80 at half the
/// increment), no field files, no refinement (the level is the scene meshed anew:
/// study_reference_scene; a .msh scene refined `level` times), and the mesh not distributed (each
/// solve is one process's run, whatever the study's MPI ranks: study_runner.hpp).
ReferenceRunSettings study_reference_settings(const StudyReferenceSpec& spec, const Scene& scene, int level,
                                              const std::vector<std::size_t>& sample_indices,
                                              LoadIncrement increment = LoadIncrement::whole);

/// The least tool travel between two samples that a study's adaptive sampling inserts, per unit
/// of the scene's own element size (at the whole increment).
inline constexpr double study_min_travel_per_element = 1.0 / 40.0;

/// The scene a study's reference solves at mesh level `level`: `scene` itself for a level >= 0
/// (its mesh refined `level` times: element size h/2^level), and for a level k < 0 the scene meshed
/// at 2^-k times its element size h (gmsh cannot un-refine a mesh, so a coarser level is a new mesh
/// of the same geometry, not nested in the finer ones). Throws std::invalid_argument below -3.
Scene study_reference_scene(const Scene& scene, int level);

/// The element size [m] of `scene`'s mesh at a study's mesh level `level`: h 2^-level.
double study_reference_element_size(const Scene& scene, int level);

/// A reference solve's identity in the cache.
struct ReferenceCacheKey {
  /// One "name = value" line per input that changes the reference's numbers (see file comment),
  /// written beside the cached profile as `key.txt`.
  std::string text;
  /// The cache entry's directory name: `<scene sha256, 16 hex>-p<degree>-L<level>-n<samples>-<sha256
  /// of text, 16 hex>` (readable prefix, exact suffix).
  std::string directory;
};

/// The cache key of `scene` solved with `settings` (as study_reference_settings makes them, or
/// `kerf calibrate`'s). The solver's own defaults that `run_reference` does not take from
/// `settings` (reference::SolverSettings tolerances, DOF limit, penalty; LoadPathSettings
/// cut-backs) enter with their current values, so a changed default also misses the cache.
/// `solver_version` is the reference's (reference::solver_version); a test may key another.
/// Throws std::runtime_error if the scene or geometry file cannot be read.
ReferenceCacheKey reference_cache_key(const Scene& scene, const ReferenceRunSettings& settings,
                                      int solver_version = reference::solver_version);

} // namespace kerf
