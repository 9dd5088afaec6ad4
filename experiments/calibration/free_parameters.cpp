#include "experiments/calibration/free_parameters.hpp"

namespace kerf {

namespace {

const FreeParameter fracture_parameters[] = {
    {"fracture", "rupture_force_per_length", "f_r", "N/m", 1.0,
     "force per unit contact length at rupture, f_r = f1(δ_r) (paper 001 §4.3)",
     [](const Scene& s) { return s.fracture->rupture_force_per_length; },
     [](Scene& s, double v) { s.fracture->rupture_force_per_length = v; }},
    {"fracture", "rupture_deflection", "δ_r", "mm", 1e-3, "deflection at rupture in deformation state 1 (paper 001 §4.3)",
     [](const Scene& s) { return s.fracture->rupture_deflection; },
     [](Scene& s, double v) { s.fracture->rupture_deflection = v; }},
    {"fracture", "crack_deflection", "δ_c", "mm", 1e-3,
     "deflection of state 2 at which f2(δ_c) = J_c and the crack extends (paper 001 §4.3, §6)",
     [](const Scene& s) { return s.fracture->crack_deflection; },
     [](Scene& s, double v) { s.fracture->crack_deflection = v; }},
};

const FreeParameter springs_parameters[] = {
    {"springs", "stiffness_scale", "s_k", "", 1.0,
     "factor on the Young's modulus the 28 spring constants are identified from (paper 000 §2.1)",
     [](const Scene& s) { return s.springs ? s.springs->stiffness_scale : 1.0; },
     [](Scene& s, double v) {
       if (!s.springs) s.springs.emplace();
       s.springs->stiffness_scale = v;
     }},
};

const FreeParameter voxel_parameters[] = {
    {"voxel", "elastic_coefficient", "E", "N/m^2", 1.0, "elastic coefficient, the stick's contact stiffness (paper 002 Table 1)",
     [](const Scene& s) { return s.voxel->elastic_coefficient; },
     [](Scene& s, double v) { s.voxel->elastic_coefficient = v; }},
    {"voxel", "critical_force_depth", "F_cd", "N", 1.0, "critical force in the depth direction (paper 002 §2.3, Table 1)",
     [](const Scene& s) { return s.voxel->critical_force_depth; },
     [](Scene& s, double v) { s.voxel->critical_force_depth = v; }},
    {"voxel", "critical_force_cutting", "F_cc", "N", 1.0, "critical force in the cutting direction (paper 002 §2.3, Table 1)",
     [](const Scene& s) { return s.voxel->critical_force_cutting; },
     [](Scene& s, double v) { s.voxel->critical_force_cutting = v; }},
    {"voxel", "damping_coefficient", "b", "N s/m^2", 1.0,
     "damping coefficient on the penetration rate (paper 002 Table 1; at the scenes' 1 mm/s its 0.5 N s/mm is 0.5 N, "
     "as much as the cutting forces); a scene without damping keeps none",
     [](const Scene& s) { return s.voxel->damping_coefficient; },
     [](Scene& s, double v) { s.voxel->damping_coefficient = v; }},
};

} // namespace

std::span<const FreeParameter> free_parameters(std::string_view model) {
  if (model == "fracture") return fracture_parameters;
  if (model == "springs") return springs_parameters;
  if (model == "voxel") return voxel_parameters;
  return {};
}

} // namespace kerf
