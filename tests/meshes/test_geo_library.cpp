// Tests of the geometry library meshes/geo/*.geo through mesh_geo: every file meshes at two
// element sizes into a valid, closed, conforming mesh whose volume and group areas equal the
// analytic values of its parameters; parameters override the defaults; bad input is a MeshError.
#include "meshes/gmsh_io.hpp"
#include "meshes/mesh_error.hpp"
#include "meshes/surface_mesh.hpp"
#include "meshes/tet_mesh.hpp"
#include "meshes/tet_quality.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace kerf {
namespace {

const std::filesystem::path k_geo_dir = KERF_GEO_DIR;

/// Analytic expectations of one geometry: cut_axis 0 -> plane x = cut_offset, 1 -> y = cut_offset.
struct GeoCase {
  std::string file;
  std::map<std::string, double> parameters;
  double volume;       ///< [m^3]
  double support_area; ///< [m^2]
  double top_area;     ///< [m^2]
  double cut_area;     ///< [m^2]
  int cut_axis;
  double cut_offset;
  std::vector<std::string> extra_groups;
};

// rect_prism defaults: 0.040 x 0.020 x 0.015, cut x = 0.020: V = L W D, base L W, top L W, cut W D.
// cut_normal 1, cut y = 0.004: cut area L D.
// tri_prism defaults: L = 0.050, b = 0.018, d = 0.017: V = L b d / 2, base L b, top 2 L sqrt((b/2)^2 + d^2),
// cut b d / 2.
// layered_block defaults: 0.040 x 0.020 x 0.020: V = L W D, base L W, top L W, cut W D.
std::vector<GeoCase> geo_cases() {
  const double tri_slant = std::sqrt(0.009 * 0.009 + 0.017 * 0.017);
  return {
      {"rect_prism.geo", {}, 0.040 * 0.020 * 0.015, 0.040 * 0.020, 0.040 * 0.020, 0.020 * 0.015, 0, 0.020, {}},
      {"rect_prism.geo", {{"cut_normal", 1}, {"cut_offset", 0.004}}, 0.040 * 0.020 * 0.015, 0.040 * 0.020,
       0.040 * 0.020, 0.040 * 0.015, 1, 0.004, {}},
      {"tri_prism.geo", {}, 0.050 * 0.018 * 0.017 / 2, 0.050 * 0.018, 2 * 0.050 * tri_slant, 0.018 * 0.017 / 2, 0,
       0.025, {}},
      {"layered_block.geo", {}, 0.040 * 0.020 * 0.020, 0.040 * 0.020, 0.040 * 0.020, 0.020 * 0.020, 0, 0.020,
       {"layer_upper", "layer_lower", "layer_interface"}},
  };
}

/// Sorted node triple -> the tetrahedra having it as a face, with the vertex opposite it.
std::map<std::array<int, 3>, std::vector<std::pair<int, int>>> faces_to_tets(const TetMesh& mesh) {
  std::map<std::array<int, 3>, std::vector<std::pair<int, int>>> faces;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      std::array<int, 3> key{};
      int j = 0;
      for (int m = 0; m < 4; ++m)
        if (m != k) key[static_cast<std::size_t>(j++)] = mesh.tets(t, m);
      std::sort(key.begin(), key.end());
      faces[key].push_back({static_cast<int>(t), mesh.tets(t, k)});
    }
  return faces;
}

/// Checks one internal surface group lying in the plane coordinate[axis] = offset: every triangle
/// is a face of exactly two tetrahedra whose opposite vertices lie on opposite sides.
void expect_conforming_internal_plane(const TetMesh& mesh, const std::string& group, int axis, double offset,
                                      double scale) {
  const SurfaceGroup* plane = mesh.find_surface_group(group);
  ASSERT_NE(plane, nullptr) << group;
  ASSERT_GT(plane->triangles.rows(), 0);
  const auto faces = faces_to_tets(mesh);
  for (Eigen::Index f = 0; f < plane->triangles.rows(); ++f) {
    std::array<int, 3> key{plane->triangles(f, 0), plane->triangles(f, 1), plane->triangles(f, 2)};
    for (const int v : key) EXPECT_NEAR(mesh.nodes(v, axis), offset, 1e-12 * scale) << group << " off its plane";
    std::sort(key.begin(), key.end());
    const auto it = faces.find(key);
    ASSERT_NE(it, faces.end()) << group << " triangle " << f << " is not a face of the mesh";
    ASSERT_EQ(it->second.size(), 2U) << group << " triangle " << f << " is not interior";
    const double side0 = mesh.nodes(it->second[0].second, axis) - offset;
    const double side1 = mesh.nodes(it->second[1].second, axis) - offset;
    EXPECT_LT(side0 * side1, 0.0) << group << " triangle " << f << ": both tetrahedra on one side";
  }
}

class GeoLibrary : public ::testing::TestWithParam<std::tuple<int, double>> {};

TEST_P(GeoLibrary, MeshesToTheAnalyticGeometry) {
  const GeoCase c = geo_cases()[static_cast<std::size_t>(std::get<0>(GetParam()))];
  const double h = std::get<1>(GetParam());
  const TetMesh mesh = mesh_geo(k_geo_dir / c.file, c.parameters, h);
  SCOPED_TRACE(c.file + " h = " + std::to_string(h));
  const double scale = std::cbrt(c.volume);

  // Sizes: coarse enough to be fast, fine enough to be a real mesh.
  EXPECT_GT(mesh.tets.rows(), 100);
  EXPECT_LT(mesh.tets.rows(), 20000);

  // Valid elements: all positive, none degenerate.
  const TetQualitySummary quality = tet_quality_summary(mesh);
  EXPECT_EQ(quality.inverted, 0);
  EXPECT_EQ(quality.degenerate, 0);
  EXPECT_GT(quality.min_volume, 0.0);

  // Volume: analytic (planar faces are meshed exactly).
  EXPECT_NEAR(mesh_volume(mesh), c.volume, 1e-9 * c.volume);
  EXPECT_NEAR(group_volume(mesh, "body"), c.volume, 1e-9 * c.volume);
  ASSERT_NE(mesh.find_volume_group("body"), nullptr);
  EXPECT_EQ(mesh.find_volume_group("body")->tets.size(), static_cast<std::size_t>(mesh.tets.rows()));

  // Groups and analytic areas.
  for (const char* name : {"support", "top", "cut_plane", "sides"}) EXPECT_NE(mesh.find_surface_group(name), nullptr) << name;
  for (const auto& name : c.extra_groups)
    EXPECT_TRUE(mesh.find_surface_group(name) != nullptr || mesh.find_volume_group(name) != nullptr) << name;
  EXPECT_NEAR(surface_group_area(mesh, "support"), c.support_area, 1e-9 * c.support_area);
  EXPECT_NEAR(surface_group_area(mesh, "top"), c.top_area, 1e-9 * c.top_area);
  EXPECT_NEAR(surface_group_area(mesh, "cut_plane"), c.cut_area, 1e-9 * c.cut_area);
  for (Eigen::Index f = 0; f < mesh.find_surface_group("support")->triangles.rows(); ++f)
    for (int j = 0; j < 3; ++j) EXPECT_EQ(mesh.nodes(mesh.find_surface_group("support")->triangles(f, j), 2), 0.0);

  // Closed boundary: the divergence theorem on it gives the tetrahedra's volume; the boundary
  // area is support + top + sides (the cut plane is interior).
  const SurfaceMesh boundary = boundary_surface(mesh);
  EXPECT_NEAR(enclosed_volume(boundary), mesh_volume(mesh), 1e-9 * c.volume);
  const double outer_area =
      surface_group_area(mesh, "support") + surface_group_area(mesh, "top") + surface_group_area(mesh, "sides");
  EXPECT_NEAR(surface_area(boundary), outer_area, 1e-9 * outer_area);

  // Face adjacency is symmetric.
  const Eigen::MatrixXi adjacency = tet_face_adjacency(mesh.tets);
  for (Eigen::Index t = 0; t < adjacency.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      const int u = adjacency(t, k);
      if (u >= 0) {
        EXPECT_TRUE((adjacency.row(u).array() == static_cast<int>(t)).any());
      }
    }

  // The cut plane is internal and conforming.
  expect_conforming_internal_plane(mesh, "cut_plane", c.cut_axis, c.cut_offset, scale);

  if (c.file == "layered_block.geo") {
    // Analytic layer volumes L W t and L W (D - t), the interface area L W.
    const double upper = 0.040 * 0.020 * 0.006;
    EXPECT_NEAR(group_volume(mesh, "layer_upper"), upper, 1e-9 * upper);
    EXPECT_NEAR(group_volume(mesh, "layer_lower"), c.volume - upper, 1e-9 * c.volume);
    EXPECT_NEAR(surface_group_area(mesh, "layer_interface"), 0.040 * 0.020, 1e-9 * 0.040 * 0.020);
    expect_conforming_internal_plane(mesh, "layer_interface", 2, 0.020 - 0.006, scale);
    EXPECT_EQ(mesh.find_volume_group("layer_upper")->tets.size() + mesh.find_volume_group("layer_lower")->tets.size(),
              static_cast<std::size_t>(mesh.tets.rows()));
  }
}

INSTANTIATE_TEST_SUITE_P(AllGeometries, GeoLibrary,
                         ::testing::Combine(::testing::Range(0, 4), ::testing::Values(0.005, 0.003)));

TEST(GeoLibraryParameters, LengthOverrideChangesVolumeAndMovesTheDefaultCut) {
  // Analytic: V = L W D with L = 0.060; cut_offset defaults to length / 2 = 0.030.
  const TetMesh mesh = mesh_geo(k_geo_dir / "rect_prism.geo", {{"length", 0.060}}, 0.005);
  const double volume = 0.060 * 0.020 * 0.015;
  EXPECT_NEAR(mesh_volume(mesh), volume, 1e-9 * volume);
  EXPECT_NEAR(mesh.nodes.col(0).maxCoeff(), 0.060, 1e-12);
  expect_conforming_internal_plane(mesh, "cut_plane", 0, 0.030, 0.06);

  // The same file afterwards without parameters is back to its defaults (no stale ONELAB value).
  const TetMesh defaults = mesh_geo(k_geo_dir / "rect_prism.geo", {}, 0.005);
  EXPECT_NEAR(mesh_volume(defaults), 0.040 * 0.020 * 0.015, 1e-9 * 0.040 * 0.020 * 0.015);

  // Every declared parameter of tri_prism and layered_block is overridable.
  const TetMesh tri = mesh_geo(k_geo_dir / "tri_prism.geo",
                               {{"length", 0.03}, {"base_width", 0.01}, {"depth", 0.02}, {"cut_offset", 0.01}}, 0.005);
  EXPECT_NEAR(mesh_volume(tri), 0.03 * 0.01 * 0.02 / 2, 1e-9 * 0.03 * 0.01 * 0.02 / 2);
  expect_conforming_internal_plane(tri, "cut_plane", 0, 0.01, 0.03);
  const TetMesh layered = mesh_geo(k_geo_dir / "layered_block.geo", {{"upper_thickness", 0.004}, {"width", 0.01}}, 0.005);
  EXPECT_NEAR(group_volume(layered, "layer_upper"), 0.040 * 0.01 * 0.004, 1e-9 * 0.040 * 0.01 * 0.004);
}

TEST(GeoLibraryParameters, MillimetreCubeWithCutAlongTheLongAxis) {
  // The sponge scenes (paper 002): a 1 mm cube, cut plane y = 0. Analytic: V = 1e-9 m^3, cut
  // area L D = 1e-6 m^2. Checks that the selection tolerance still works at this scale.
  const TetMesh mesh = mesh_geo(k_geo_dir / "rect_prism.geo",
                                {{"length", 0.001}, {"width", 0.001}, {"depth", 0.001}, {"cut_normal", 1}, {"cut_offset", 0}},
                                0.0002);
  EXPECT_NEAR(mesh_volume(mesh), 1e-9, 1e-9 * 1e-9);
  EXPECT_NEAR(surface_group_area(mesh, "cut_plane"), 1e-6, 1e-9 * 1e-6);
  EXPECT_NEAR(surface_group_area(mesh, "support"), 1e-6, 1e-9 * 1e-6);
  EXPECT_TRUE(tet_quality_summary(mesh).valid());
  expect_conforming_internal_plane(mesh, "cut_plane", 1, 0.0, 0.001);
}

TEST(GeoLibraryParameters, UnknownParameterIsAnErrorNamingFileAndParameter) {
  try {
    (void)mesh_geo(k_geo_dir / "rect_prism.geo", {{"lenght", 0.05}}, 0.005);
    FAIL() << "expected MeshError";
  } catch (const MeshError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("rect_prism.geo"), std::string::npos) << message;
    EXPECT_NE(message.find("lenght"), std::string::npos) << message;
    EXPECT_NE(message.find("length"), std::string::npos) << message; // lists the declared names
    EXPECT_NE(message.find("cut_offset"), std::string::npos) << message;
  }
}

TEST(GeoLibraryParameters, MissingFileIsAnErrorNamingIt) {
  try {
    (void)mesh_geo(k_geo_dir / "no_such_shape.geo", {}, 0.005);
    FAIL() << "expected MeshError";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_shape.geo"), std::string::npos) << e.what();
  }
}

TEST(GeoLibraryParameters, GeoErrorIsAMeshErrorAndGmshRecovers) {
  // cut_offset outside the body: the .geo's own Error(...) becomes a MeshError naming the file.
  try {
    (void)mesh_geo(k_geo_dir / "rect_prism.geo", {{"cut_offset", 0.5}}, 0.005);
    FAIL() << "expected MeshError";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("rect_prism.geo"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cut_offset"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)mesh_geo(k_geo_dir / "rect_prism.geo", {}, -1.0), MeshError);
  EXPECT_THROW((void)mesh_geo(k_geo_dir / "rect_prism.geo", {{"length", std::nan("")}}, 0.005), MeshError);
  // A syntax error in a .geo.
  const auto broken = std::filesystem::temp_directory_path() / "kerf_test_broken.geo";
  {
    std::ofstream out(broken);
    out << "SetFactory(\"OpenCASCADE\");\nBox(1) = {0, 0, 0, 1, 1;\n";
  }
  EXPECT_THROW((void)mesh_geo(broken, {}, 0.5), MeshError);
  try {
    (void)mesh_geo(broken, {{"length", 1.0}}, 0.5); // the syntax error wins over "unknown parameter"
    FAIL() << "expected MeshError";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("syntax error"), std::string::npos) << e.what();
  }
  // Defaults that fail on their own but are fixed by the override: the override wins.
  const auto fixable = std::filesystem::temp_directory_path() / "kerf_test_fixable.geo";
  {
    std::ofstream out(fixable);
    out << "SetFactory(\"OpenCASCADE\");\n"
           "DefineConstant[ size = {-1, Name \"Parameters/size\"} ];\n"
           "If (size <= 0)\n  Error(\"size must be positive\");\nEndIf\n"
           "Box(1) = {0, 0, 0, size, size, size};\nPhysical Volume(\"body\") = {1};\n";
  }
  EXPECT_THROW((void)mesh_geo(fixable, {}, 0.5), MeshError);
  const TetMesh cube = mesh_geo(fixable, {{"size", 0.01}}, 0.004);
  EXPECT_NEAR(mesh_volume(cube), 1e-6, 1e-15); // analytic: size^3
  std::filesystem::remove(fixable);
  std::filesystem::remove(broken);
  // gmsh is still usable after the errors.
  const TetMesh mesh = mesh_geo(k_geo_dir / "rect_prism.geo", {}, 0.006);
  EXPECT_NEAR(mesh_volume(mesh), 0.040 * 0.020 * 0.015, 1e-9 * 0.040 * 0.020 * 0.015);
}

} // namespace
} // namespace kerf
