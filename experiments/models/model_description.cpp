#include "experiments/models/model_description.hpp"

namespace kerf {

namespace {

const ModelDescription descriptions[] = {
    {"fracture", "energy-based sharp cutting: deformation, rupture, cutting (f = J_c l), layers, pre-sliding friction",
      "paper 001 §4, §6, Fig. 11",
      PhenomenonSet{Phenomenon::deformation, Phenomenon::cutting, Phenomenon::friction, Phenomenon::layers},
      "one blade"},
    {"edge", "discretised blade edge: stiffness x disparity per point, shear-limited cutting resistance, friction, drag; voxel collision; geometric cut off the servo thread; with a stylus, the cut piece pulled by the spring network",
      "paper 000 §3.1-3.3 (with a stylus §4 and §2.1)",
      PhenomenonSet{Phenomenon::deformation, Phenomenon::cutting, Phenomenon::friction, Phenomenon::layers},
      "one blade, or one blade then one sphere (stylus)"},
    {"voxel", "polygon surface + local voxel grid: surface points advanced past critical forces, DCS, clip friction (Eq. 1)",
      "paper 002 §2.3-2.4, Table 1",
      PhenomenonSet{Phenomenon::deformation, Phenomenon::cutting, Phenomenon::friction},
      "one sphere (cutting stick), or one blade (a knife: the stick at its point)"},
    {"springs", "cubic 28-spring network around the stylus(es), E and ν identified, embedding, tearing; --integrator explicit|implicit|static; "
                 "on a one-blade cutting scene the deformation phase only (the edge presses the network: no cut, no friction)",
      "paper 000 §2.1, §2.2", PhenomenonSet{Phenomenon::deformation, Phenomenon::tearing, Phenomenon::cutting, Phenomenon::friction},
      "one or two spheres (styluses), or one blade (deformation phase)"},
};

} // namespace

std::span<const ModelDescription> model_catalogue() { return descriptions; }

const ModelDescription* find_model(std::string_view name) {
  for (const ModelDescription& d : descriptions)
    if (d.name == name) return &d;
  return nullptr;
}

} // namespace kerf
