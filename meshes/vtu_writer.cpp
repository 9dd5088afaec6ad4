#include "meshes/vtu_writer.hpp"

#include "meshes/atomic_file.hpp"
#include "meshes/mesh_error.hpp"
#include "meshes/tet_quality.hpp"

#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <numbers>
#include <string>

namespace kerf {

namespace {

/// A #rows by k matrix as a VTK array with k components, named `name`.
vtkNew<vtkDoubleArray> to_vtk_array(const std::string& name, const Eigen::MatrixXd& values) {
  vtkNew<vtkDoubleArray> array;
  array->SetName(name.c_str());
  array->SetNumberOfComponents(static_cast<int>(values.cols()));
  array->SetNumberOfTuples(values.rows());
  for (Eigen::Index i = 0; i < values.rows(); ++i)
    for (Eigen::Index j = 0; j < values.cols(); ++j) array->SetComponent(i, static_cast<int>(j), values(i, j));
  return array;
}

} // namespace

void write_vtu(const TetMesh& mesh, const std::filesystem::path& vtu, const std::vector<VtuField>& point_data,
               const std::vector<VtuField>& cell_data) {
  const std::string file = vtu.string();
  const Eigen::Index node_count = mesh.nodes.rows();
  const Eigen::Index tet_count = mesh.tets.rows();
  for (const auto& [name, values] : point_data)
    if (values.rows() != node_count || values.cols() < 1)
      throw MeshError(file + ": point field '" + name + "' has " + std::to_string(values.rows()) + " rows, the mesh " +
                      std::to_string(node_count) + " nodes");
  for (const auto& [name, values] : cell_data)
    if (values.rows() != tet_count || values.cols() < 1)
      throw MeshError(file + ": cell field '" + name + "' has " + std::to_string(values.rows()) + " rows, the mesh " +
                      std::to_string(tet_count) + " tetrahedra");
  for (Eigen::Index t = 0; t < tet_count; ++t)
    for (int j = 0; j < 4; ++j)
      if (mesh.tets(t, j) < 0 || mesh.tets(t, j) >= node_count)
        throw MeshError(file + ": tetrahedron " + std::to_string(t) + " references missing node " + std::to_string(mesh.tets(t, j)));

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(node_count);
  for (Eigen::Index v = 0; v < node_count; ++v) points->SetPoint(v, mesh.nodes(v, 0), mesh.nodes(v, 1), mesh.nodes(v, 2));
  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(points);
  grid->Allocate(tet_count);
  for (Eigen::Index t = 0; t < tet_count; ++t) {
    const vtkIdType ids[4] = {mesh.tets(t, 0), mesh.tets(t, 1), mesh.tets(t, 2), mesh.tets(t, 3)};
    grid->InsertNextCell(VTK_TETRA, 4, ids);
  }

  // Per-cell quality and region, always written.
  std::vector<std::string> names;
  for (const auto& group : mesh.volume_groups) names.push_back(group.name);
  const Eigen::VectorXi regions = tet_regions(mesh, names);
  vtkNew<vtkIntArray> region;
  region->SetName("region");
  region->SetNumberOfTuples(tet_count);
  Eigen::MatrixXd volume(tet_count, 1);
  Eigen::MatrixXd dihedral(tet_count, 1);
  Eigen::MatrixXd ratio(tet_count, 1);
  for (Eigen::Index t = 0; t < tet_count; ++t) {
    const Eigen::Vector3d a = mesh.nodes.row(mesh.tets(t, 0)).transpose();
    const Eigen::Vector3d b = mesh.nodes.row(mesh.tets(t, 1)).transpose();
    const Eigen::Vector3d c = mesh.nodes.row(mesh.tets(t, 2)).transpose();
    const Eigen::Vector3d d = mesh.nodes.row(mesh.tets(t, 3)).transpose();
    region->SetValue(t, regions(t));
    volume(t, 0) = signed_volume(a, b, c, d);
    dihedral(t, 0) = min_dihedral_angle(a, b, c, d) * 180.0 / std::numbers::pi;
    ratio(t, 0) = radius_ratio(a, b, c, d);
  }
  grid->GetCellData()->AddArray(region);
  grid->GetCellData()->AddArray(to_vtk_array("signed_volume", volume));
  grid->GetCellData()->AddArray(to_vtk_array("min_dihedral_deg", dihedral));
  grid->GetCellData()->AddArray(to_vtk_array("radius_ratio", ratio));
  for (const auto& [name, values] : cell_data) grid->GetCellData()->AddArray(to_vtk_array(name, values));
  for (const auto& [name, values] : point_data) grid->GetPointData()->AddArray(to_vtk_array(name, values));

  try {
    write_atomically(vtu, [&](const std::filesystem::path& temporary) {
      vtkNew<vtkXMLUnstructuredGridWriter> writer;
      writer->SetFileName(temporary.string().c_str());
      writer->SetInputData(grid);
      writer->SetDataModeToAppended();
      writer->EncodeAppendedDataOff();
      if (writer->Write() != 1) throw MeshError(file + ": VTK could not write " + temporary.string());
    });
  } catch (const MeshError&) {
    throw;
  } catch (const std::exception& e) {
    throw MeshError(file + ": writing failed: " + e.what());
  }
}

} // namespace kerf
