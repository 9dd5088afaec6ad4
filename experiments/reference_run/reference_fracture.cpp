#include "experiments/reference_run/reference_fracture.hpp"

#include "meshes/crack_split.hpp"

#include <algorithm>
#include <limits>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace kerf {

CrackPathInfo add_crack_path(const Scene& scene, reference::FiniteStrainProblem& problem, ReferenceFracture mode,
                             int refinements, double viscous_time) {
  CrackPathInfo info;
  if (!(viscous_time >= 0.0) || !std::isfinite(viscous_time))
    throw std::invalid_argument("reference: scene '" + scene.name + "': the cohesive viscous time must be >= 0 s, got " +
                                std::to_string(viscous_time));
  if (mode == ReferenceFracture::off) return info;
  const bool fractures = scene.phenomena.contains(Phenomenon::cutting) || scene.phenomena.contains(Phenomenon::tearing);
  const bool has_plane = problem.mesh.find_surface_group("cut_plane") != nullptr;
  const bool has_law = scene.material.cohesive_strength > 0.0 && scene.material.fracture_toughness > 0.0;
  if (mode == ReferenceFracture::automatic && !(fractures && has_plane && has_law)) return info;
  if (!has_plane)
    throw std::invalid_argument("reference: scene '" + scene.name + "' (" + scene.file.string() +
                                "): fracture needs a conformingly meshed surface group 'cut_plane' (the crack path)");
  if (!has_law)
    throw std::invalid_argument("reference: scene '" + scene.name + "' (" + scene.file.string() +
                                "): fracture needs [material] cohesive_strength and fracture_toughness");

  const CrackSplit split = split_along_surface(problem.mesh, "cut_plane");
  problem.mesh = split.mesh;
  reference::CohesiveInterfaceSpec spec;
  spec.plus_surface = "cut_plane+";
  spec.minus_surface = "cut_plane-";
  spec.law.cohesive_strength = scene.material.cohesive_strength;
  spec.law.fracture_toughness = scene.material.fracture_toughness;
  // η = σ_c τ / δ_f (Gao & Bower 2004, Eq. 5, with their relaxation time written as τ).
  spec.law.viscosity = spec.law.cohesive_strength * viscous_time / spec.law.failure_opening();
  problem.cohesive = spec;
  info.viscosity = spec.law.viscosity;

  info.active = true;
  info.interface_triangles = static_cast<std::size_t>(split.plus_faces.rows());
  for (Eigen::Index f = 0; f < split.plus_faces.rows(); ++f) {
    const Eigen::Vector3d a = split.mesh.nodes.row(split.plus_faces(f, 0)), b = split.mesh.nodes.row(split.plus_faces(f, 1)),
                          c = split.mesh.nodes.row(split.plus_faces(f, 2));
    info.interface_area += 0.5 * (b - a).cross(c - a).norm();
  }
  const CohesiveZone zone = scene_cohesive_zone(scene);
  info.zone_length = zone.length();
  // The element size where the crack runs, measured on the split mesh (whatever graded it).
  const Tool* blade = nullptr;
  for (const Tool& t : scene.tools)
    if (t.kind == Tool::Kind::blade) blade = &t;
  const Eigen::Vector3d c = blade != nullptr ? blade->blade.cutting_direction : Eigen::Vector3d::UnitZ();
  const double reach = blade != nullptr ? blade_reach(*blade) : 0.0; // along c
  // The representative size of the triangles there: the side of the equilateral triangle of their
  // mean area, h = (4 Ā / √3)^½ (the surface analogue of Celik et al. 2008's h = (V/N)^⅓).
  double area = 0.0;
  std::size_t count = 0;
  for (int pass = 0; pass < 2 && count == 0; ++pass) // pass 1: the whole path, when the blade reaches none of it
    for (Eigen::Index f = 0; f < split.plus_faces.rows(); ++f) {
      Eigen::Vector3d v[3];
      for (int j = 0; j < 3; ++j) v[j] = split.mesh.nodes.row(split.plus_faces(f, j)).transpose();
      const Eigen::Vector3d centroid = (v[0] + v[1] + v[2]) / 3.0;
      if (pass == 0 && blade != nullptr && centroid.dot(c) > reach + info.zone_length) continue; // beyond the blade's reach
      area += 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).norm();
      ++count;
    }
  const double mean_area = count > 0 ? area / static_cast<double>(count) : 0.0;
  info.element_size = std::sqrt(4.0 * mean_area / std::sqrt(3.0)) / std::pow(2.0, refinements);
  info.elements_in_zone = reference::elements_in_cohesive_zone(info.zone_length, info.element_size);
  if (info.elements_in_zone < reference::minimum_elements_in_cohesive_zone) {
    char buf[640];
    std::snprintf(buf, sizeof buf,
                  "the mesh is too coarse for the cohesive zone: the zone of %.3g mm (Rice's l_cz = %.3g mm, the "
                  "blade's wedge s_f = %.3g mm; σ_c = %.3g MPa, J_c = %.3g J/m²) spans %.2f elements of %.3g mm where "
                  "the crack runs, fewer than %.0f (Turon et al. 2007); mesh the scene for the reference "
                  "(scene_mesh, MeshPurpose::reference) or refine (--refine), or the force and dissipation depend on "
                  "the mesh",
                  info.zone_length * 1e3, zone.rice * 1e3, zone.wedge * 1e3, scene.material.cohesive_strength * 1e-6,
                  scene.material.fracture_toughness, info.elements_in_zone, info.element_size * 1e3,
                  reference::minimum_elements_in_cohesive_zone);
    info.warning = buf;
  }
  return info;
}

void EnergyBookkeeping::add_sample(const std::vector<Eigen::Vector3d>& positions, const std::vector<Eigen::Vector3d>& forces,
                                   double strain_energy, const reference::CohesiveSummary& interface, double contact_energy,
                                   double kinetic_energy, double damping_dissipation) {
  if (positions.size() != forces.size()) throw std::invalid_argument("energy bookkeeping: one force per tool position");
  if (!m_positions.empty()) {
    if (m_positions.size() != positions.size()) throw std::invalid_argument("energy bookkeeping: the tool count changed");
    for (std::size_t t = 0; t < positions.size(); ++t)
      m_work += 0.5 * (forces[t] + m_forces[t]).dot(positions[t] - m_positions[t]); // trapezoid rule
  }
  m_positions = positions;
  m_forces = forces;
  m_strain = strain_energy;
  m_interface = interface;
  m_contact = contact_energy;
  m_kinetic = kinetic_energy;
  m_damping = damping_dissipation;
}

double EnergyBookkeeping::cohesive_time_integration() const {
  // Only the dynamic step measures the trapezoid work (CohesiveSummary::trapezoid_work = 0 otherwise).
  if (m_interface.trapezoid_work == 0.0) return 0.0;
  return m_interface.trapezoid_work - m_interface.stored_energy - m_interface.dissipated_energy;
}

double EnergyBookkeeping::balance_error() const {
  const double accounted =
      m_strain + m_interface.stored_energy + m_contact + m_kinetic + m_interface.dissipated_energy +
      m_interface.viscous_dissipation + m_damping; // the kinks' error is not booked (reported alone)
  const double scale = std::max({std::abs(m_work), std::abs(accounted), 1e-300});
  return (m_work - accounted) / scale;
}

nlohmann::json EnergyBookkeeping::to_json() const {
  nlohmann::json positions = nlohmann::json::array(), forces = nlohmann::json::array();
  for (std::size_t t = 0; t < m_positions.size(); ++t) {
    positions.push_back({m_positions[t].x(), m_positions[t].y(), m_positions[t].z()});
    forces.push_back({m_forces[t].x(), m_forces[t].y(), m_forces[t].z()});
  }
  return {{"external_work_J", m_work},
          {"stored_elastic_energy_J", m_strain},
          {"interface_energy_J", m_interface.stored_energy},
          {"contact_energy_J", m_contact},
          {"kinetic_energy_J", m_kinetic},
          {"cohesive_dissipation_J", m_interface.dissipated_energy},
          {"viscous_dissipation_J", m_interface.viscous_dissipation},
          {"damping_dissipation_J", m_damping},
          {"cohesive_time_integration_J", cohesive_time_integration()},
          {"cohesive_trapezoid_work_J", m_interface.trapezoid_work},
          {"friction_dissipation_J", 0.0},
          {"failed_area_m2", m_interface.failed_area},
          {"balance_error", balance_error()},
          {"last_positions_m", positions},
          {"last_forces_on_body_N", forces}};
}

EnergyBookkeeping EnergyBookkeeping::from_json(const nlohmann::json& j) {
  EnergyBookkeeping e;
  e.m_work = j.at("external_work_J").get<double>();
  e.m_strain = j.at("stored_elastic_energy_J").get<double>();
  e.m_interface.stored_energy = j.at("interface_energy_J").get<double>();
  e.m_contact = j.value("contact_energy_J", 0.0); // absent in checkpoints written before it was booked
  e.m_kinetic = j.value("kinetic_energy_J", 0.0); // absent in quasi-static runs' checkpoints before the dynamic step
  e.m_interface.trapezoid_work = j.value("cohesive_trapezoid_work_J", 0.0); // likewise
  e.m_damping = j.value("damping_dissipation_J", 0.0); // absent before the Kelvin–Voigt damping
  e.m_interface.dissipated_energy = j.at("cohesive_dissipation_J").get<double>();
  e.m_interface.viscous_dissipation = j.at("viscous_dissipation_J").get<double>();
  e.m_interface.failed_area = j.at("failed_area_m2").get<double>();
  for (const auto& p : j.at("last_positions_m")) e.m_positions.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
  for (const auto& f : j.at("last_forces_on_body_N")) e.m_forces.emplace_back(f[0].get<double>(), f[1].get<double>(), f[2].get<double>());
  return e;
}

} // namespace kerf
