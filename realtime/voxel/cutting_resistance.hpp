#pragma once
// The two resistances paper 002 §2.4 adds to its point-cutting model so that the stick feels
// like a buried knife edge: depth cutting stiffness (DCS) and clip friction force (CFF, Eq. 1).
// Pure mechanics, free functions; SI units.

namespace kerf {

/// DCS coefficient of paper 002 §2.4: "0.066 E/mm", the increment of the cutting force per
/// millimetre of cutting depth relative to the material stiffness E, measured there on sponge.
inline constexpr double depth_cutting_stiffness_per_mm = 0.066;

/// Depth cutting stiffness force of paper 002 §2.4 [N]: the cutting force grows by 0.066 E per
/// millimetre of depth,
///   F_dcs = 0.066 E d,
/// with `material_stiffness` E the paper's material (contact) stiffness [N/m] (Table 1's elastic
/// coefficient, read as documented in docs/models.md, section voxel) and `depth` d >= 0 the
/// depth of the cutting edge below the body's surface [m]. Zero for d <= 0.
[[nodiscard]] double depth_cutting_stiffness_force(double material_stiffness, double depth);

/// Clip friction force of paper 002 Eq. (1) [N]: the friction from the material the edge's
/// thickness pushes aside,
///   Fh = M E Cw dz (sqrt(Cl^2 + Cw^2) - Cl) / Cl * cos(atan(Cl / Cw)),
/// with M the friction coefficient, E the material modulus [Pa] (E Cw dz is a force: Cw dz is
/// the deformed area, §2.4), Cw half the cutting edge width [m] > 0, dz the cutting depth [m]
/// and Cl the cutting length [m]. Zero for dz <= 0 or Cl <= 0 (no cut yet: Eq. 1 diverges like
/// Cw/Cl as Cl -> 0, so callers start it after the first advance, Cl >= one advance length).
[[nodiscard]] double clip_friction_force(double friction_coefficient, double modulus, double half_edge_width,
                                         double depth, double cutting_length);

} // namespace kerf
