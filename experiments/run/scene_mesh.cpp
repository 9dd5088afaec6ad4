#include "experiments/run/scene_mesh.hpp"

#include "meshes/gmsh_io.hpp"
#include "meshes/mesh_error.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace kerf {

std::string grasp_surface_name(int k) { return "grasp" + std::to_string(k); }

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
  if (purpose == MeshPurpose::reference && finest_rim > 0.0) p["grasp_element_size"] = finest_rim;
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
