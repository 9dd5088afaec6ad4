// Tests of meshes/gmsh_io: .msh 4.1 round trip, atomic writing, reading files written by hand
// (unnamed groups, inverted tetrahedra), errors naming the file, and meshing a closed STL.
#include "meshes/gmsh_io.hpp"

#include "meshes/mesh_error.hpp"
#include "meshes/tet_quality.hpp"

#include "tests/meshes/one_tetrahedron.hpp"

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <unistd.h>

namespace kerf {
namespace {

namespace fs = std::filesystem;

/// A fresh, empty directory for one test.
fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_gmsh_io_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

bool has_temporary_file(const fs::path& dir) {
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename().string().find(".tmp.") != std::string::npos) return true;
  return false;
}

void expect_same_mesh(const TetMesh& a, const TetMesh& b) {
  ASSERT_EQ(a.nodes.rows(), b.nodes.rows());
  ASSERT_EQ(a.tets.rows(), b.tets.rows());
  // gmsh writes coordinates with 16 significant digits: equal to ~1e-16 relative.
  EXPECT_LE((a.nodes - b.nodes).cwiseAbs().maxCoeff(), 1e-15 * a.nodes.cwiseAbs().maxCoeff());
  EXPECT_EQ(a.tets, b.tets);
  ASSERT_EQ(a.volume_groups.size(), b.volume_groups.size());
  for (std::size_t g = 0; g < a.volume_groups.size(); ++g) {
    EXPECT_EQ(a.volume_groups[g].name, b.volume_groups[g].name);
    EXPECT_EQ(a.volume_groups[g].tag, b.volume_groups[g].tag);
    EXPECT_EQ(a.volume_groups[g].tets, b.volume_groups[g].tets);
  }
  ASSERT_EQ(a.surface_groups.size(), b.surface_groups.size());
  for (std::size_t g = 0; g < a.surface_groups.size(); ++g) {
    EXPECT_EQ(a.surface_groups[g].name, b.surface_groups[g].name);
    EXPECT_EQ(a.surface_groups[g].tag, b.surface_groups[g].tag);
    EXPECT_EQ(a.surface_groups[g].triangles, b.surface_groups[g].triangles);
  }
}

TEST(GmshIo, MshRoundTripOfAGeneratedMesh) {
  const TetMesh mesh = mesh_geo(fs::path(KERF_GEO_DIR) / "layered_block.geo", {}, 0.006);
  const fs::path file = scratch_dir("round_trip") / "block.msh";
  write_msh(mesh, file);
  std::ifstream in(file);
  std::string first_two(15, '\0');
  in.read(first_two.data(), 15);
  EXPECT_EQ(first_two.substr(0, 15), "$MeshFormat\n4.1");
  expect_same_mesh(mesh, read_msh(file));
  EXPECT_FALSE(has_temporary_file(file.parent_path()));
}

TEST(GmshIo, MshRoundTripOfAHandBuiltMeshWithOverlappingGroups) {
  // Two tetrahedra sharing face (0,1,2); tet 1 in no group except `all`; triangle (0,1,2) in two
  // surface groups; group tags that collide are renumbered, unique ones kept.
  TetMesh mesh;
  mesh.nodes.resize(5, 3);
  mesh.nodes << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.3, 0.3, -1;
  mesh.tets.resize(2, 4);
  mesh.tets << 0, 1, 2, 3, 0, 2, 1, 4;
  mesh.volume_groups.push_back({"all", 5, {0, 1}});
  mesh.volume_groups.push_back({"upper", 9, {0}});
  SurfaceGroup interface{"interface", 3, Eigen::MatrixXi(1, 3)};
  interface.triangles << 0, 1, 2;
  SurfaceGroup skin{"skin", 4, Eigen::MatrixXi(2, 3)};
  skin.triangles << 0, 1, 2, 0, 3, 1;
  mesh.surface_groups = {interface, skin};
  const fs::path file = scratch_dir("hand") / "two.msh";
  write_msh(mesh, file);
  expect_same_mesh(mesh, read_msh(file));

  // A tetrahedron in no volume group is still written (SaveAll switches on).
  TetMesh loose = mesh;
  loose.volume_groups = {{"upper", 9, {0}}};
  write_msh(loose, file);
  const TetMesh back = read_msh(file);
  EXPECT_EQ(back.tets.rows(), 2);
  EXPECT_EQ(back.tets, loose.tets);
}

TEST(GmshIo, ReadsUnnamedGroupsAndKeepsTheFilesOrientation) {
  // MSH 2.2 written by hand: one inverted tetrahedron (det < 0) in physical volume 7 without a
  // name, one triangle in physical surface 3 without a name.
  const fs::path file = scratch_dir("hand22") / "inverted.msh";
  std::ofstream(file) << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n"
                         "1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n$Elements\n2\n"
                         "1 4 2 7 1 1 3 2 4\n2 2 2 3 1 1 2 3\n$EndElements\n";
  const TetMesh mesh = read_msh(file);
  ASSERT_EQ(mesh.tets.rows(), 1);
  // The right-corner tetrahedron, volume 1/6, stored inverted: read as written (-1/6) so the
  // quality summary reports it instead of a silently flipped element.
  EXPECT_NEAR(mesh_volume(mesh), -1.0 / 6.0, 1e-15);
  EXPECT_EQ(tet_quality_summary(mesh).inverted, 1);
  ASSERT_EQ(mesh.volume_groups.size(), 1U);
  EXPECT_EQ(mesh.volume_groups[0].name, "physical_7");
  ASSERT_EQ(mesh.surface_groups.size(), 1U);
  EXPECT_EQ(mesh.surface_groups[0].name, "physical_3");
  EXPECT_EQ(mesh.surface_groups[0].triangles.rows(), 1);
}

TEST(GmshIo, ReadErrorsNameTheFile) {
  try {
    (void)read_msh("/nonexistent/kerf/missing.msh");
    FAIL() << "expected MeshError";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.msh"), std::string::npos) << e.what();
  }
  const fs::path garbage = scratch_dir("garbage") / "garbage.msh";
  std::ofstream(garbage) << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\nthis is not a mesh\n";
  try {
    (void)read_msh(garbage);
    FAIL() << "expected MeshError";
  } catch (const MeshError& e) {
    EXPECT_NE(std::string(e.what()).find("garbage.msh"), std::string::npos) << e.what();
  }
}

TEST(GmshIo, WritingToAnUnwritablePlaceThrowsAndLeavesNoTemporaryFile) {
  const TetMesh mesh = test::one_tetrahedron();
  const fs::path dir = scratch_dir("unwritable");
  // The "directory" is a regular file: nothing can be created under it.
  const fs::path not_a_dir = dir / "file";
  std::ofstream(not_a_dir) << "x";
  EXPECT_THROW(write_msh(mesh, not_a_dir / "out.msh"), MeshError);
  // The target is an existing directory: the temporary file is written, the rename fails.
  fs::create_directories(dir / "taken.msh");
  EXPECT_THROW(write_msh(mesh, dir / "taken.msh"), MeshError);
  EXPECT_FALSE(has_temporary_file(dir));
  // A read-only directory (only meaningful when not running as root).
  if (::geteuid() != 0) {
    const fs::path read_only = dir / "read_only";
    fs::create_directories(read_only);
    fs::permissions(read_only, fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_THROW(write_msh(mesh, read_only / "out.msh"), MeshError);
    EXPECT_FALSE(has_temporary_file(read_only));
    fs::permissions(read_only, fs::perms::owner_all);
  }
  // An invalid mesh is rejected before anything is written.
  TetMesh broken = mesh;
  broken.tets(0, 3) = 17;
  EXPECT_THROW(write_msh(broken, dir / "broken.msh"), MeshError);
  EXPECT_FALSE(fs::exists(dir / "broken.msh"));
}

/// ASCII STL of the box [0, a] x [0, b] x [0, c], two outward triangles per face.
void write_box_stl(const fs::path& file, double a, double b, double c) {
  const double p[8][3] = {{0, 0, 0}, {a, 0, 0}, {0, b, 0}, {a, b, 0}, {0, 0, c}, {a, 0, c}, {0, b, c}, {a, b, c}};
  // Corner index x + 2y + 4z; each face as a quad ordered counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  const double normals[6][3] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0}, {0, 1, 0}, {-1, 0, 0}, {1, 0, 0}};
  std::ofstream out(file);
  out.precision(17);
  out << "solid box\n";
  for (int f = 0; f < 6; ++f)
    for (const auto& tri : {std::array<int, 3>{quads[f][0], quads[f][1], quads[f][2]},
                            std::array<int, 3>{quads[f][0], quads[f][2], quads[f][3]}}) {
      out << " facet normal " << normals[f][0] << ' ' << normals[f][1] << ' ' << normals[f][2] << "\n  outer loop\n";
      for (const int v : tri) out << "   vertex " << p[v][0] << ' ' << p[v][1] << ' ' << p[v][2] << '\n';
      out << "  endloop\n endfacet\n";
    }
  out << "endsolid box\n";
}

TEST(GmshIo, MeshesAClosedStlBox) {
  // The box 30 mm x 20 mm x 10 mm written in millimetres, scaled to metres.
  const fs::path file = scratch_dir("stl") / "box.stl";
  write_box_stl(file, 30, 20, 10);
  const TetMesh mesh = mesh_stl(file, 0.004, 1e-3);
  const double volume = 0.030 * 0.020 * 0.010; // analytic: a b c
  EXPECT_NEAR(mesh_volume(mesh), volume, 1e-9 * volume);
  const TetQualitySummary quality = tet_quality_summary(mesh);
  EXPECT_TRUE(quality.valid());
  ASSERT_NE(mesh.find_volume_group("body"), nullptr);
  EXPECT_EQ(mesh.find_volume_group("body")->tets.size(), static_cast<std::size_t>(mesh.tets.rows()));
  const double area = 2 * (0.030 * 0.020 + 0.020 * 0.010 + 0.010 * 0.030); // analytic: 2 (ab + bc + ca)
  EXPECT_NEAR(surface_group_area(mesh, "boundary"), area, 1e-9 * area);
  EXPECT_NEAR(mesh.nodes.col(0).maxCoeff(), 0.030, 1e-12);

  EXPECT_THROW((void)mesh_stl(file.parent_path() / "missing.stl", 0.004), MeshError);
  EXPECT_THROW((void)mesh_stl(file, 0.004, 0.0), MeshError);
}

} // namespace
} // namespace kerf
