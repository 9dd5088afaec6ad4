#pragma once
// The measured responses that parameterise paper 001's sharp-interaction model (§4.3, §6):
// deflection responses per unit contact length in deformation states 1 and 2, the rupture
// point, the lateral wall and the pre-sliding friction.

namespace kerf {

/// Paper 001 §6: f1(δ) = f_r (δ/δ_r)^i and f2(δ) = J_c (δ/δ_c)^j, forces per unit contact
/// length [N/m], with i, j in {1, 2, 3}. Rupture when the deflection in state 1 reaches δ_r
/// (§4.3: f_r = f1(δ_r)); the crack then extends to c = x - δ_c, where f2(δ_c) = J_c.
struct FractureResponseParameters {
  double rupture_force_per_length = 0.0; ///< f_r [N/m] > 0
  double rupture_deflection = 0.0;       ///< δ_r [m] > 0
  int deformation_1_exponent = 1;        ///< i in {1,2,3}
  double crack_deflection = 0.0;         ///< δ_c [m] > 0
  int deformation_2_exponent = 1;        ///< j in {1,2,3}
  double lateral_stiffness = 0.0;        ///< bilateral wall keeping the blade in its plane [N/m] >= 0
  /// Hayward & Armstrong (2000) pre-sliding friction: adhesion stiffness [N/m] > 0 and the
  /// fraction of the breakaway displacement below which the contact sticks purely elastically.
  double presliding_stiffness = 0.0;
  double presliding_stick_ratio = 0.5;   ///< z_stick / z_max in [0, 1)
};

} // namespace kerf
