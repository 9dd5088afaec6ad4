// Tests of meshes/vtu_writer: write a mesh with fields, read it back with VTK's own reader.
#include "meshes/vtu_writer.hpp"

#include "meshes/mesh_error.hpp"
#include "meshes/tet_quality.hpp"

#include <gtest/gtest.h>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include <unistd.h>

namespace kerf {
namespace {

namespace fs = std::filesystem;

/// Two tetrahedra sharing a face: the right-corner tetrahedron (volume 1/6) and its mirror below
/// z = 0, in volume groups `upper` (tet 0) and `body` (both).
TetMesh two_tets() {
  TetMesh mesh;
  mesh.nodes.resize(5, 3);
  mesh.nodes << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1;
  mesh.tets.resize(2, 4);
  mesh.tets << 0, 1, 2, 3, 0, 2, 1, 4;
  mesh.volume_groups.push_back({"upper", 1, {0}});
  mesh.volume_groups.push_back({"body", 2, {0, 1}});
  return mesh;
}

fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("kerf_test_vtu_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(VtuWriter, WritesPointsCellsAndDataThatVtkReadsBack) {
  const TetMesh mesh = two_tets();
  Eigen::MatrixXd displacement(5, 3);
  displacement.setRandom();
  Eigen::MatrixXd damage(2, 1);
  damage << 0.25, 0.75;
  const fs::path file = scratch_dir("write") / "two.vtu";
  write_vtu(mesh, file, {{"displacement", displacement}}, {{"damage", damage}});

  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(file.string().c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  ASSERT_NE(grid, nullptr);
  EXPECT_EQ(grid->GetNumberOfPoints(), 5);
  EXPECT_EQ(grid->GetNumberOfCells(), 2);
  for (const char* name : {"region", "signed_volume", "min_dihedral_deg", "radius_ratio", "damage"})
    EXPECT_NE(grid->GetCellData()->GetArray(name), nullptr) << name;
  vtkDataArray* point_field = grid->GetPointData()->GetArray("displacement");
  ASSERT_NE(point_field, nullptr);
  EXPECT_EQ(point_field->GetNumberOfComponents(), 3);
  EXPECT_EQ(point_field->GetComponent(4, 2), displacement(4, 2)); // binary, exact

  // Values: both right-corner tetrahedra have volume 1/6, min dihedral acos(1/sqrt 3) and radius
  // ratio sqrt 3 - 1 (closed forms, see test_tet_quality); region = first group holding the cell.
  vtkDataArray* volume = grid->GetCellData()->GetArray("signed_volume");
  vtkDataArray* dihedral = grid->GetCellData()->GetArray("min_dihedral_deg");
  vtkDataArray* ratio = grid->GetCellData()->GetArray("radius_ratio");
  vtkDataArray* region = grid->GetCellData()->GetArray("region");
  for (vtkIdType c = 0; c < 2; ++c) {
    EXPECT_NEAR(volume->GetComponent(c, 0), 1.0 / 6.0, 1e-15);
    EXPECT_NEAR(dihedral->GetComponent(c, 0), std::acos(1.0 / std::sqrt(3.0)) * 180.0 / std::numbers::pi, 1e-12);
    EXPECT_NEAR(ratio->GetComponent(c, 0), std::sqrt(3.0) - 1.0, 1e-14);
  }
  EXPECT_EQ(region->GetComponent(0, 0), 0); // `upper` is listed first
  EXPECT_EQ(region->GetComponent(1, 0), 1);
  EXPECT_EQ(grid->GetCellData()->GetArray("damage")->GetComponent(1, 0), 0.75);
  EXPECT_EQ(grid->GetCellType(0), 10); // VTK_TETRA
}

TEST(VtuWriter, RejectsMismatchedFieldsAndUnwritablePaths) {
  const TetMesh mesh = two_tets();
  const fs::path dir = scratch_dir("errors");
  EXPECT_THROW(write_vtu(mesh, dir / "a.vtu", {{"bad", Eigen::MatrixXd::Zero(4, 1)}}), MeshError);
  EXPECT_THROW(write_vtu(mesh, dir / "b.vtu", {}, {{"bad", Eigen::MatrixXd::Zero(3, 1)}}), MeshError);
  EXPECT_FALSE(fs::exists(dir / "a.vtu"));
  EXPECT_FALSE(fs::exists(dir / "b.vtu"));
  // Under a regular file nothing can be created.
  std::ofstream(dir / "file") << "x";
  EXPECT_THROW(write_vtu(mesh, dir / "file" / "c.vtu"), MeshError);
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().filename().string().find(".tmp."), std::string::npos) << entry.path();
}

} // namespace
} // namespace kerf
