#pragma once
// The reference run's checkpoint (reference_run.hpp: dir/checkpoint.bin, written every few solved
// samples and at a stop, read by `kerf reference --resume`). Binary, native byte order (a
// checkpoint is resumed on the machine that wrote it):
// "KERFREF4", scene sha256, degree, refinements, process count, time integration (0 quasi-static,
// 1 dynamic), damping (0 none, 1 the scene's Kelvin–Voigt damping in the dynamic step), sample
// indices, targets solved, the last converged load, the solver state (global DOF order, which
// depends on the process count; a dynamic run's also holds the velocity and acceleration, a damped
// one the damping dissipation), the profile rows, the per-sample manifest records (JSON), the
// solve seconds, and (version 4) the load path's interface step. Version 3 ("KERFREF3", written before the damping) is the same without the
// damping field and is read as undamped; version 2 ("KERFREF2", before the dynamic step) has no
// time integration either and is read as quasi-static.
//
// Includes reference/*.hpp only, which include no deal.II.

#include "formats/profile/force_profile.hpp"
#include "reference/finite_strain_solver.hpp"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace kerf {

/// What a reference run needs to continue where it stopped.
struct ReferenceCheckpoint {
  std::string scene_sha256;
  int degree = 0, refinements = 0;
  int processes = 1; ///< MPI processes the mesh was distributed over
  bool dynamic = false; ///< the run's time integration: the dynamic step (ReferenceRunSettings::dynamic)
  bool damped = false;  ///< the dynamic step modelled the scene's Kelvin–Voigt damping (ReferenceRunSettings::damping)
  std::vector<std::size_t> indices; ///< trajectory samples the run solves
  std::size_t solved = 0;           ///< how many of `indices` are solved
  reference::LoadState last;        ///< the last converged load (its time is not stored)
  /// The load path's interface step (reference::LoadPath::interface_step) [s]; 0 before version 4.
  double interface_step = 0.0;
  std::vector<double> state;        ///< the solver's state at `last` (FiniteStrainSolver::set_state)
  ForceProfile profile;             ///< one row per solved sample
  nlohmann::json samples = nlohmann::json::array(); ///< the manifest record of each solved sample
  double solve_seconds = 0.0;       ///< [s] the solves so far
};

/// Writes `c` to `file` atomically (meshes/atomic_file.hpp). Throws std::runtime_error naming the
/// file when it cannot be written whole (a full disk).
void write_reference_checkpoint(const ReferenceCheckpoint& c, const std::filesystem::path& file);

/// Reads a checkpoint written by write_reference_checkpoint. Throws std::runtime_error naming the
/// file on anything else: a wrong magic, a truncated or corrupt file (a count larger than the
/// bytes left, a bad mode, a sample record run_reference cannot resume from, more samples solved
/// than requested).
ReferenceCheckpoint read_reference_checkpoint(const std::filesystem::path& file);

} // namespace kerf
