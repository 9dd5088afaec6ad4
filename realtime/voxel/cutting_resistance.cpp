#include "realtime/voxel/cutting_resistance.hpp"

#include <cmath>

namespace kerf {

double depth_cutting_stiffness_force(double material_stiffness, double depth) {
  if (!(depth > 0.0)) return 0.0;
  // Paper 002 §2.4: F_dcs = 0.066 E d (0.066 E per mm of depth, E the material stiffness).
  return depth_cutting_stiffness_per_mm * material_stiffness * depth;
}

double clip_friction_force(double friction_coefficient, double modulus, double half_edge_width, double depth,
                           double cutting_length) {
  if (!(depth > 0.0) || !(cutting_length > 0.0) || !(half_edge_width > 0.0)) return 0.0;
  const double cl = cutting_length;
  const double cw = half_edge_width;
  // Paper 002 Eq. (1): Fh = M E Cw dz (sqrt(Cl^2 + Cw^2) - Cl)/Cl cos(atan(Cl/Cw)).
  // sqrt(Cl^2+Cw^2) - Cl is written as Cw^2 / (sqrt(Cl^2+Cw^2) + Cl): the same number without the
  // cancellation that loses all digits once Cl >> Cw.
  const double hyp = std::hypot(cl, cw);
  const double stretch = cw * cw / (hyp + cl) / cl;
  return friction_coefficient * modulus * cw * depth * stretch * std::cos(std::atan(cl / cw));
}

} // namespace kerf
