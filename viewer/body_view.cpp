#include "viewer/body_view.hpp"

#include "viewer/von_mises.hpp"

#include <Eigen/Geometry>
#include <vtkActor.h>
#include <vtkArrowSource.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataSetSurfaceFilter.h>
#include <vtkDoubleArray.h>
#include <vtkLookupTable.h>
#include <vtkMatrix4x4.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnstructuredGrid.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kerf {

std::string_view to_string(Colouring colouring) {
  return colouring == Colouring::displacement ? "displacement" : "von-mises";
}

std::optional<Colouring> colouring_from_string(std::string_view name) {
  if (name == "displacement") return Colouring::displacement;
  if (name == "von-mises") return Colouring::von_mises;
  return std::nullopt;
}

namespace {

vtkSmartPointer<vtkPoints> make_points(const Eigen::MatrixXd& p) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(p.rows());
  for (Eigen::Index i = 0; i < p.rows(); ++i) points->SetPoint(i, p(i, 0), p(i, 1), p(i, 2));
  return points;
}

vtkSmartPointer<vtkCellArray> make_cells(const Eigen::MatrixXi& cells) {
  auto array = vtkSmartPointer<vtkCellArray>::New();
  std::vector<vtkIdType> ids(static_cast<std::size_t>(cells.cols()));
  for (Eigen::Index c = 0; c < cells.rows(); ++c) {
    for (Eigen::Index k = 0; k < cells.cols(); ++k) ids[static_cast<std::size_t>(k)] = cells(c, k);
    array->InsertNextCell(cells.cols(), ids.data());
  }
  return array;
}

/// A rotation-and-scale taking the unit x axis to `v` (length and direction), the other two
/// axes to perpendiculars of the same length, placed at `origin`.
vtkSmartPointer<vtkMatrix4x4> arrow_matrix(const Eigen::Vector3d& origin, const Eigen::Vector3d& v) {
  const double length = v.norm();
  const Eigen::Vector3d d = v / length;
  const Eigen::Vector3d helper = std::abs(d.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d n1 = d.cross(helper).normalized();
  const Eigen::Vector3d n2 = d.cross(n1);
  auto m = vtkSmartPointer<vtkMatrix4x4>::New();
  for (int r = 0; r < 3; ++r) {
    m->SetElement(r, 0, length * d[r]);
    m->SetElement(r, 1, length * n1[r]);
    m->SetElement(r, 2, length * n2[r]);
    m->SetElement(r, 3, origin[r]);
  }
  return m;
}

} // namespace

vtkSmartPointer<vtkDataSet> body_dataset(const BodyGeometry& body, const ElasticConstants* elastic) {
  if (body.points.rows() != body.rest.rows())
    throw std::invalid_argument("viewer: body has " + std::to_string(body.points.rows()) + " points but " +
                                std::to_string(body.rest.rows()) + " rest positions");
  auto displacement = vtkSmartPointer<vtkDoubleArray>::New();
  displacement->SetName("displacement");
  displacement->SetNumberOfComponents(3);
  displacement->SetNumberOfTuples(body.points.rows());
  for (Eigen::Index i = 0; i < body.points.rows(); ++i) {
    const Eigen::Vector3d u = (body.points.row(i) - body.rest.row(i)).transpose();
    displacement->SetTuple3(i, u.x(), u.y(), u.z());
  }
  if (body.tets.rows() > 0) {
    auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
    grid->SetPoints(make_points(body.points));
    grid->SetCells(VTK_TETRA, make_cells(body.tets));
    grid->GetPointData()->AddArray(displacement);
    if (elastic) {
      const Eigen::VectorXd s =
          von_mises_stress(body.rest, body.points, body.tets, elastic->youngs_modulus, elastic->poisson_ratio);
      auto stress = vtkSmartPointer<vtkDoubleArray>::New();
      stress->SetName("von_mises");
      stress->SetNumberOfTuples(s.size());
      for (Eigen::Index t = 0; t < s.size(); ++t) stress->SetValue(t, s(t));
      grid->GetCellData()->AddArray(stress);
    }
    return grid;
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(make_points(body.points));
  poly->SetPolys(make_cells(body.triangles));
  poly->GetPointData()->AddArray(displacement);
  return poly;
}

BodyView::BodyView(vtkRenderer* renderer, Colouring colouring, std::vector<ToolGlyph> tools)
    : m_renderer(renderer), m_colouring(colouring), m_glyphs(std::move(tools)) {
  m_lut = vtkSmartPointer<vtkLookupTable>::New();
  m_lut->SetHueRange(0.667, 0.0); // blue (0) to red (max)
  m_lut->SetVectorModeToMagnitude();
  m_lut->SetTableRange(0.0, 1.0);
  m_lut->Build();

  m_surface = vtkSmartPointer<vtkDataSetSurfaceFilter>::New();
  m_mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  m_mapper->SetInputConnection(m_surface->GetOutputPort());
  m_mapper->SetLookupTable(m_lut);
  m_mapper->UseLookupTableScalarRangeOn();
  m_mapper->ScalarVisibilityOn();
  m_mapper->SetColorModeToMapScalars();
  m_mapper->SelectColorArray(colouring == Colouring::displacement ? "displacement" : "von_mises");
  m_mapper->SetScalarModeToUsePointFieldData();
  m_body = vtkSmartPointer<vtkActor>::New();
  m_body->SetMapper(m_mapper);
  m_body->GetProperty()->SetSpecular(0.2);
  m_body->VisibilityOff(); // until a body is set
  renderer->AddActor(m_body);

  m_overlay_data = vtkSmartPointer<vtkPolyData>::New();
  auto overlay_mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  overlay_mapper->SetInputData(m_overlay_data);
  overlay_mapper->ScalarVisibilityOff();
  m_overlay = vtkSmartPointer<vtkActor>::New();
  m_overlay->SetMapper(overlay_mapper);
  m_overlay->GetProperty()->SetColor(0.15, 0.15, 0.15);
  m_overlay->GetProperty()->SetLineWidth(1.5);
  m_overlay->GetProperty()->LightingOff();
  renderer->AddActor(m_overlay);

  auto arrow = vtkSmartPointer<vtkArrowSource>::New();
  arrow->SetTipResolution(16);
  arrow->SetShaftResolution(16);
  for (const ToolGlyph& g : m_glyphs) {
    auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
    if (g.blade) {
      // The edge and a flank behind it (half the edge length high), in tool-local coordinates.
      const BladeShape& shape = g.blade_shape;
      const Eigen::Vector3d half = 0.5 * shape.edge_length * shape.edge_direction.normalized();
      const Eigen::Vector3d back = -0.5 * shape.edge_length * shape.cutting_direction.normalized();
      Eigen::MatrixXd corners(4, 3);
      corners.row(0) = (-half).transpose();
      corners.row(1) = half.transpose();
      corners.row(2) = (half + back).transpose();
      corners.row(3) = (-half + back).transpose();
      auto quad = vtkSmartPointer<vtkPolyData>::New();
      quad->SetPoints(make_points(corners));
      Eigen::MatrixXi face(1, 4);
      face << 0, 1, 2, 3;
      quad->SetPolys(make_cells(face));
      mapper->SetInputData(quad);
    } else {
      auto sphere = vtkSmartPointer<vtkSphereSource>::New();
      sphere->SetRadius(g.radius);
      sphere->SetThetaResolution(32);
      sphere->SetPhiResolution(24);
      mapper->SetInputConnection(sphere->GetOutputPort());
    }
    auto actor = vtkSmartPointer<vtkActor>::New();
    actor->SetMapper(mapper);
    actor->GetProperty()->SetColor(0.85, 0.75, 0.35);
    renderer->AddActor(actor);
    m_tools.push_back(actor);

    auto arrow_mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
    arrow_mapper->SetInputConnection(arrow->GetOutputPort());
    auto arrow_actor = vtkSmartPointer<vtkActor>::New();
    arrow_actor->SetMapper(arrow_mapper);
    arrow_actor->GetProperty()->SetColor(0.1, 0.6, 0.1);
    arrow_actor->VisibilityOff();
    renderer->AddActor(arrow_actor);
    m_arrows.push_back(arrow_actor);
  }

  m_text = vtkSmartPointer<vtkTextActor>::New();
  m_text->GetTextProperty()->SetFontSize(14);
  m_text->GetTextProperty()->SetColor(0.0, 0.0, 0.0);
  m_text->GetTextProperty()->SetVerticalJustificationToTop();
  m_text->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  m_text->SetPosition(0.01, 0.98);
  renderer->AddViewProp(m_text);

  m_bar = vtkSmartPointer<vtkScalarBarActor>::New();
  m_bar->SetLookupTable(m_lut);
  m_bar->SetTitle(colouring == Colouring::displacement ? "|u| [m]" : "von Mises [Pa]");
  m_bar->SetLabelFormat("%.2g");
  m_bar->SetNumberOfLabels(3);
  m_bar->SetOrientationToHorizontal();
  m_bar->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  m_bar->SetPosition(0.55, 0.02); // room right of the bar for half of its last label
  m_bar->SetWidth(0.38);
  m_bar->SetHeight(0.1);
  m_bar->GetTitleTextProperty()->SetColor(0.0, 0.0, 0.0);
  m_bar->GetLabelTextProperty()->SetColor(0.0, 0.0, 0.0);
  m_bar->GetTitleTextProperty()->SetFontSize(12);
  m_bar->GetLabelTextProperty()->SetFontSize(12);
  m_bar->SetUnconstrainedFontSize(true);
  renderer->AddViewProp(m_bar);
}

BodyView::~BodyView() = default;

void BodyView::set_body(vtkDataSet* body) {
  m_surface->SetInputData(body);
  const char* name = m_colouring == Colouring::displacement ? "displacement" : "von_mises";
  vtkDataArray* array = body->GetPointData()->GetArray(name);
  if (array) {
    m_mapper->SetScalarModeToUsePointFieldData();
  } else {
    array = body->GetCellData()->GetArray(name);
    m_mapper->SetScalarModeToUseCellFieldData();
  }
  if (!array)
    throw std::invalid_argument(std::string("viewer: the body carries no \"") + name + "\" data to colour by");
  // The top of the automatic colour range: the 99th percentile of the values, so that a few
  // extreme elements (a sliver, a contact spike) do not wash the rest of the body into one colour.
  std::vector<double> values(static_cast<std::size_t>(array->GetNumberOfTuples()));
  for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i) {
    if (array->GetNumberOfComponents() == 3) {
      double v[3];
      array->GetTuple(i, v);
      values[static_cast<std::size_t>(i)] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    } else {
      values[static_cast<std::size_t>(i)] = array->GetComponent(i, 0);
    }
  }
  m_data_max = 0.0;
  if (!values.empty()) {
    const auto k = static_cast<std::ptrdiff_t>(0.99 * static_cast<double>(values.size() - 1));
    std::nth_element(values.begin(), values.begin() + k, values.end());
    m_data_max = values[static_cast<std::size_t>(k)];
  }
  m_body->VisibilityOn();
}

void BodyView::set_overlay(const Eigen::MatrixXd& points, const Eigen::MatrixXi& lines) {
  m_overlay_data->SetPoints(make_points(points));
  m_overlay_data->SetLines(make_cells(lines));
  m_overlay_data->Modified();
}

void BodyView::set_overlay_visible(bool visible) {
  m_overlay_visible = visible;
  m_overlay->SetVisibility(visible);
}

void BodyView::set_tools(std::span<const Eigen::Vector3d> positions, std::span<const Eigen::Vector3d> forces) {
  for (std::size_t i = 0; i < m_tools.size(); ++i) {
    if (i >= positions.size()) {
      m_tools[i]->VisibilityOff();
      m_arrows[i]->VisibilityOff();
      continue;
    }
    m_tools[i]->VisibilityOn();
    m_tools[i]->SetPosition(positions[i].x(), positions[i].y(), positions[i].z());
    const Eigen::Vector3d f = i < forces.size() ? forces[i] : Eigen::Vector3d::Zero();
    const Eigen::Vector3d arrow = m_force_scale * f;
    if (arrow.norm() > 1e-9) {
      m_arrows[i]->SetUserMatrix(arrow_matrix(positions[i], arrow));
      m_arrows[i]->VisibilityOn();
    } else {
      m_arrows[i]->VisibilityOff();
    }
  }
}

void BodyView::set_text(const std::string& text) { m_text->SetInput(text.c_str()); }

void BodyView::set_legend_visible(bool visible) { m_bar->SetVisibility(visible); }

void BodyView::set_colour_range(double max) {
  m_lut->SetTableRange(0.0, max > 0.0 ? max : 1e-12);
  m_lut->Build();
}

} // namespace kerf
