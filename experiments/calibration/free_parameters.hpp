#pragma once
// The free parameters of each fast model that calibration fits (docs/studies.md): where each
// lives in a Scene, and the key and unit it is written with in a parameter file that a scene
// includes (docs/scenes.md, "Including parameter files").

#include "formats/scene/scene.hpp"

#include <span>
#include <string_view>

namespace kerf {

/// One continuous, positive parameter of a model. It is written as `key = "VALUE UNIT"` in the
/// `[models.<model>]` table of a parameter file; the scene reader converts it back to SI.
struct FreeParameter {
  std::string_view model;    ///< catalogue name: fracture, springs, voxel
  std::string_view key;      ///< key in [models.<model>]
  std::string_view symbol;   ///< the paper's symbol, for reports ("f_r")
  std::string_view unit;     ///< unit it is written in ("N/m", "mm", "N", "N/m^2", "" for a number)
  double unit_value;         ///< SI value of one `unit` (1e-3 for mm)
  std::string_view meaning;  ///< one line, with the paper and section
  double (*get)(const Scene&);       ///< SI; the scene must have the model's section
  void (*set)(Scene&, double value); ///< SI > 0
};

/// The parameters calibration fits for `model`:
/// - fracture (paper 001 §4.3, §6): f_r, δ_r, δ_c — with the integer exponents i, j of f1 and f2
///   chosen by enumeration (calibration.hpp);
/// - springs (paper 000 §2.1): the stiffness scale on the modulus the spring constants are
///   identified from;
/// - voxel (paper 002 Table 1): the elastic coefficient (stiffness) and the critical forces in the
///   depth and cutting directions.
/// Empty for a model without calibrated parameters.
std::span<const FreeParameter> free_parameters(std::string_view model);

} // namespace kerf
