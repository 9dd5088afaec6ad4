#include "formats/scene/scene_mesh.hpp"

#include "formats/scene/cohesive_zone.hpp"
#include "meshes/gmsh_io.hpp"
#include "meshes/mesh_error.hpp"
#include "reference/cohesive/cohesive_zone.hpp"

#include <algorithm>
#include <set>
#include <sstream>
#include <stdexcept>

namespace kerf {

std::string grasp_surface_name(int k) { return "grasp" + std::to_string(k); }

namespace {

/// The crack path's grading for a reference mesh (see scene_mesh.hpp): on a geometry that declares
/// rect_prism.geo's `cut_element_size` grading, a cutting or tearing scene with a cohesive law gets
/// elements of min(h0, zone / 3) on its cut plane (cohesive_zone.hpp), from the
/// top down to one zone length below the deepest point a blade's edge reaches (the whole depth for a
/// tear), growing to the element size h at half the distance (cut_grading_distance), all scaled by
/// `scale`. The deepest point is the lower end of the edge at the lowest sample of the trajectory
/// (for a downward cut with a horizontal edge, the whole edge). Nothing for a blade whose cutting
/// direction points upwards (the grading box grows from the top).
void add_crack_path_grading(const Scene& scene, double nominal, double scale, std::map<std::string, double>& p) {
  const SceneGeometry& g = scene.geometry;
  if (g.kind != SceneGeometry::Kind::geo || !scene_has_cohesive_law(scene)) return;
  const std::set<std::string> declared = geo_parameter_names(g.source);
  if (declared.count("cut_element_size") == 0 || declared.count("cut_refine_depth") == 0) return;
  const CohesiveZone zone = scene_cohesive_zone(scene);
  const double size = std::min(nominal, zone.length() / reference::minimum_elements_in_cohesive_zone) * scale;
  const double h = g.element_size;
  if (!(size < h)) return; // the uniform mesh already resolves the zone
  double refine_depth = -1.0; // < 0: the geometry's default (its whole depth)
  for (const Tool& t : scene.tools) {
    if (t.kind != Tool::Kind::blade) continue;
    if (!(t.blade.cutting_direction.z() < 0.0)) return; // not into the top face: the box grading does not apply
    const auto top = g.parameters.find("depth");
    if (top == g.parameters.end() || declared.count("depth") == 0) return;
    const double lowest = blade_lowest_edge_point(t);
    refine_depth = std::min(std::max(top->second - lowest + zone.length() * scale, size), top->second);
  }
  p["cut_element_size"] = size;
  p["cut_far_size"] = h;
  p["cut_grading_distance"] = (h - size) / 0.5; // the size grows by half the distance
  if (refine_depth > 0.0) p["cut_refine_depth"] = refine_depth;
}

} // namespace

std::map<std::string, double> scene_mesh_parameters(const Scene& scene, MeshPurpose purpose) {
  const SceneGeometry& g = scene.geometry;
  std::map<std::string, double> p;
  // Every size derived here scales with the element size the scene is meshed at.
  const double nominal = g.nominal_element_size > 0.0 ? g.nominal_element_size : g.element_size;
  const double scale = g.element_size / nominal;
  int k = 0;
  double finest_rim = 0.0;
  for (const Tool& tool : scene.tools) {
    if (tool.kind != Tool::Kind::sphere || !tool.grasp_radius) continue;
    ++k;
    if (g.kind != SceneGeometry::Kind::geo)
      throw std::invalid_argument("scene '" + scene.name + "' (" + scene.file.string() + "): stylus '" + tool.name +
                                  "' grasps a disc (grasp_radius), which needs a .geo geometry that declares "
                                  "grasp1_radius, grasp1_x and grasp1_y (meshes/geo/rect_prism.geo)");
    if (k > 2)
      throw std::invalid_argument("scene '" + scene.name + "' (" + scene.file.string() +
                                  "): at most two styluses grasp the surface (grasp1, grasp2); stylus '" + tool.name +
                                  "' is the third");
    const double a = *tool.grasp_radius;
    const std::string prefix = "grasp" + std::to_string(k);
    p[prefix + "_radius"] = a;
    p[prefix + "_x"] = tool.trajectory.start.x();
    p[prefix + "_y"] = tool.trajectory.start.y();
    const double rim = std::min(nominal, a / grasp_rim_elements_per_radius) * scale;
    finest_rim = finest_rim > 0.0 ? std::min(finest_rim, rim) : rim;
  }
  if (purpose == MeshPurpose::reference && finest_rim > 0.0) p["grasp_element_size"] = g.grasp_element_size.value_or(finest_rim);
  if (purpose == MeshPurpose::reference) add_crack_path_grading(scene, nominal, scale, p);
  return p;
}

TetMesh scene_mesh(const Scene& scene, MeshPurpose purpose) {
  const SceneGeometry& g = scene.geometry;
  TetMesh mesh;
  switch (g.kind) {
  case SceneGeometry::Kind::geo: {
    std::map<std::string, double> parameters = g.parameters;
    for (const auto& [name, value] : scene_mesh_parameters(scene, purpose)) {
      if (parameters.count(name) != 0)
        throw MeshError(scene.file.string() + ": [geometry.parameters] " + name +
                        " is derived by kerf from the scene's tools; remove it from the scene file");
      parameters[name] = value;
    }
    mesh = mesh_geo(g.source, parameters, g.element_size);
    break;
  }
  case SceneGeometry::Kind::stl: mesh = mesh_stl(g.source, g.element_size, g.stl_scale); break;
  case SceneGeometry::Kind::msh: mesh = read_msh(g.source); break;
  }
  const TetQualitySummary q = tet_quality_summary(mesh);
  if (!q.valid()) {
    std::ostringstream msg;
    msg << g.source.string() << ": the mesh has " << q.inverted << " inverted and " << q.degenerate
        << " degenerate tetrahedra (smallest signed volume " << q.min_volume
        << " m^3); expected every tetrahedron to have positive volume";
    throw MeshError(msg.str());
  }
  if (!mesh.find_volume_group("body") && g.kind != SceneGeometry::Kind::stl)
    throw MeshError(g.source.string() + ": no physical volume named \"body\"");
  int k = 0;
  for (const Tool& tool : scene.tools)
    if (tool.kind == Tool::Kind::sphere && tool.grasp_radius && !mesh.find_surface_group(grasp_surface_name(++k)))
      throw MeshError(g.source.string() + ": no physical surface \"" + grasp_surface_name(k) + "\" for the disc stylus '" +
                      tool.name + "' grasps");
  return mesh;
}

} // namespace kerf
