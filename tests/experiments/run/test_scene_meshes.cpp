// Every scene in experiments/scenes meshes as the scene says: the volume equals the analytic
// volume of its geometry (box L W D, triangular prism L b h / 2) to 1e-9 relative, every
// tetrahedron is positive, the physical groups are there, and `cut_plane` is conforming — each
// of its triangles is a face of exactly two tetrahedra, one on each side of the plane.

#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "meshes/tet_quality.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>

using namespace kerf;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> scene_names() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes"))
    if (e.path().extension() == ".toml") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

double analytic_volume(const Scene& s) {
  const auto& p = s.geometry.parameters;
  const std::string geo = s.geometry.source.filename().string();
  if (geo == "tri_prism.geo") return p.at("length") * p.at("base_width") * p.at("depth") / 2.0;
  return p.at("length") * p.at("width") * p.at("depth"); // rect_prism.geo, layered_block.geo
}

class SceneMeshes : public ::testing::TestWithParam<std::string> {};

} // namespace

TEST_P(SceneMeshes, MatchTheirGeometry) {
  const Scene scene = read_scene(fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / (GetParam() + ".toml"));
  ASSERT_EQ(scene.geometry.kind, SceneGeometry::Kind::geo);
  const TetMesh mesh = scene_mesh(scene);
  const TetQualitySummary q = tet_quality_summary(mesh);
  EXPECT_EQ(q.inverted, 0);
  EXPECT_EQ(q.degenerate, 0);
  EXPECT_NEAR(q.total_volume, analytic_volume(scene), 1e-9 * analytic_volume(scene));
  for (const char* group : {"support", "top", "cut_plane"}) EXPECT_NE(mesh.find_surface_group(group), nullptr) << group;
  EXPECT_NE(mesh.find_volume_group("body"), nullptr);
  for (const Support& s : scene.supports) EXPECT_NE(mesh.find_surface_group(s.surface), nullptr) << s.surface;
  for (const Material& m : scene.layers) EXPECT_NE(mesh.find_volume_group(m.region), nullptr) << m.region;

  // Conformity of the cut plane: map each tetrahedron face (sorted nodes) to the tetrahedra
  // holding it and the side of the plane their opposite vertex lies on.
  const SurfaceGroup& cut = *mesh.find_surface_group("cut_plane");
  ASSERT_GT(cut.triangles.rows(), 0);
  const Eigen::Vector3d a = mesh.nodes.row(cut.triangles(0, 0)), b = mesh.nodes.row(cut.triangles(0, 1)),
                        c = mesh.nodes.row(cut.triangles(0, 2));
  const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
  std::map<std::array<int, 3>, std::vector<double>> faces;
  for (int t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      std::array<int, 3> f{};
      for (int j = 0, n = 0; j < 4; ++j)
        if (j != k) f[static_cast<std::size_t>(n++)] = mesh.tets(t, j);
      std::sort(f.begin(), f.end());
      faces[f].push_back(normal.dot(Eigen::Vector3d(mesh.nodes.row(mesh.tets(t, k))) - a));
    }
  double area = 0.0;
  for (int i = 0; i < cut.triangles.rows(); ++i) {
    std::array<int, 3> f{cut.triangles(i, 0), cut.triangles(i, 1), cut.triangles(i, 2)};
    for (int j = 0; j < 3; ++j) // every node of the cut plane lies in it
      EXPECT_NEAR(normal.dot(Eigen::Vector3d(mesh.nodes.row(f[static_cast<std::size_t>(j)])) - a), 0.0, 1e-12);
    std::sort(f.begin(), f.end());
    const auto it = faces.find(f);
    ASSERT_NE(it, faces.end()) << "cut_plane triangle " << i << " is not a tetrahedron face";
    ASSERT_EQ(it->second.size(), 2u) << "cut_plane triangle " << i;
    EXPECT_LT(it->second[0] * it->second[1], 0.0) << "both tetrahedra on one side, triangle " << i;
    const Eigen::Vector3d p = mesh.nodes.row(f[0]), q = mesh.nodes.row(f[1]), r = mesh.nodes.row(f[2]);
    area += 0.5 * (q - p).cross(r - p).norm();
  }
  // The cut plane spans the whole cross-section of the body (analytic, by geometry and plane).
  const auto& prm = scene.geometry.parameters;
  const std::string geo = scene.geometry.source.filename().string();
  double section = 0.0;
  if (geo == "tri_prism.geo") section = prm.at("base_width") * prm.at("depth") / 2.0;
  else if (prm.count("cut_normal") && prm.at("cut_normal") == 1.0) section = prm.at("length") * prm.at("depth");
  else section = prm.at("width") * prm.at("depth");
  EXPECT_NEAR(area, section, 1e-9 * section);
}

INSTANTIATE_TEST_SUITE_P(AllScenes, SceneMeshes, ::testing::ValuesIn(scene_names()),
                         [](const auto& info) { return info.param; });

// A scene meshes the same whatever the process meshed before it: gmsh keeps its options from one
// model to the next (gmsh::clear() empties the model, not the options), and a .geo that grades its
// mesh with a size field turns Mesh.MeshSizeFromPoints and Mesh.MeshSizeExtendFromBoundary off. A
// study meshes the scenes' reference and model meshes one after another in one process, so without
// a reset a mesh depended on which scenes were meshed before it (a resumed study, whose first scene's
// reference came from the cache, solved the second on another mesh). Expected: node for node equal.
TEST(SceneMeshHistory, AMeshDoesNotDependOnTheMeshesBeforeIt) {
  const fs::path scenes = fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes";
  const Scene wedge = read_scene(scenes / "potato_wedge_cut.toml");
  const Scene clay = read_scene(scenes / "clay_pull.toml");
  for (const MeshPurpose purpose : {MeshPurpose::scene, MeshPurpose::reference}) {
    SCOPED_TRACE(purpose == MeshPurpose::scene ? "scene mesh" : "reference mesh");
    const TetMesh clay_first = scene_mesh(clay, purpose);
    const TetMesh first = scene_mesh(wedge, purpose);
    (void)scene_mesh(clay, MeshPurpose::reference); // a graded mesh in between
    const TetMesh again = scene_mesh(wedge, purpose);
    const TetMesh clay_again = scene_mesh(clay, purpose);
    ASSERT_EQ(first.nodes.rows(), again.nodes.rows());
    ASSERT_EQ(first.tets.rows(), again.tets.rows());
    EXPECT_EQ(first.nodes, again.nodes);
    EXPECT_EQ(first.tets, again.tets);
    ASSERT_EQ(clay_first.nodes.rows(), clay_again.nodes.rows());
    EXPECT_EQ(clay_first.nodes, clay_again.nodes);
  }
}
