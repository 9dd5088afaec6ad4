#include "formats/scene/cohesive_zone.hpp"

#include "formats/trajectory/trajectory.hpp"
#include "reference/cohesive/cohesive_zone.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kerf {

double blade_reach(const Tool& blade) {
  double reach = -std::numeric_limits<double>::infinity();
  for (const ToolState& st : sample(blade.trajectory).samples)
    reach = std::max(reach, st.position.dot(blade.blade.cutting_direction));
  return reach;
}

double blade_lowest_edge_point(const Tool& blade) {
  const double half_rise = 0.5 * blade.blade.edge_length * std::abs(blade.blade.edge_direction.z());
  double lowest = std::numeric_limits<double>::infinity();
  for (const ToolState& st : sample(blade.trajectory).samples) lowest = std::min(lowest, st.position.z() - half_rise);
  return lowest;
}

CohesiveZone scene_cohesive_zone(const Scene& scene) {
  CohesiveZone z;
  const Material& m = scene.material;
  if (!(m.cohesive_strength > 0.0 && m.fracture_toughness > 0.0)) return z;
  z.rice = reference::cohesive_zone_length(m.youngs_modulus, m.poisson_ratio, m.fracture_toughness, m.cohesive_strength);
  const double failure_opening = 2.0 * m.fracture_toughness / m.cohesive_strength; // bilinear law: δ_f = 2 J_c/σ_c
  for (const Tool& t : scene.tools)
    if (t.kind == Tool::Kind::blade) z.wedge = std::max(z.wedge, failure_opening / (2.0 * std::tan(0.5 * t.blade.wedge_angle)));
  return z;
}

bool scene_has_cohesive_law(const Scene& scene) {
  const bool fractures = scene.phenomena.contains(Phenomenon::cutting) || scene.phenomena.contains(Phenomenon::tearing);
  return fractures && scene.material.cohesive_strength > 0.0 && scene.material.fracture_toughness > 0.0;
}

} // namespace kerf
