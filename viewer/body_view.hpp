#pragma once
// BodyView: one body drawn in one VTK renderer — its surface coloured by displacement or von
// Mises stress, the model's structure as a wire-frame overlay (toggled), the tool(s), the force
// on each tool as an arrow, and a text block. The caller feeds it data; it owns the actors.

#include "meshes/blade_shape.hpp"
#include "viewer/body_geometry.hpp"

#include <Eigen/Core>
#include <vtkSmartPointer.h>

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

class vtkActor;
class vtkDataSet;
class vtkDataSetSurfaceFilter;
class vtkLookupTable;
class vtkPolyData;
class vtkPolyDataMapper;
class vtkRenderer;
class vtkScalarBarActor;
class vtkTextActor;

namespace kerf {

/// What the surface is coloured by.
enum class Colouring {
  displacement, ///< |u| [m], point data "displacement"
  von_mises     ///< σ_vM [Pa], point or cell data "von_mises"
};
/// "displacement", "von-mises".
std::string_view to_string(Colouring colouring);
std::optional<Colouring> colouring_from_string(std::string_view name);

/// A tool as drawn: a sphere of `radius` centred on the tool position, or a blade whose edge
/// (length `edge_length` along `edge_direction` of `blade_shape`, centred on the tool position)
/// leads a flank drawn behind it (against its `cutting_direction`).
struct ToolGlyph {
  bool blade = false;
  double radius = 0.0;    ///< sphere [m]
  BladeShape blade_shape; ///< blade (meshes/blade_shape.hpp)
};

/// Elastic constants for colouring a BodyGeometry by von Mises stress (von_mises.hpp).
struct ElasticConstants {
  double youngs_modulus = 0.0; ///< E [Pa]
  double poisson_ratio = 0.0;  ///< ν
};

/// The body as VTK data: an unstructured grid of its tetrahedra (or a polydata of its triangles)
/// at the deformed positions, with point data "displacement" (points − rest, [m]) and, when
/// `elastic` is given and the body has tetrahedra, cell data "von_mises" [Pa].
vtkSmartPointer<vtkDataSet> body_dataset(const BodyGeometry& body, const ElasticConstants* elastic);

class BodyView {
public:
  /// Adds the actors to `renderer` (kept alive by it). One glyph per tool.
  BodyView(vtkRenderer* renderer, Colouring colouring, std::vector<ToolGlyph> tools);
  ~BodyView();
  BodyView(const BodyView&) = delete;
  BodyView& operator=(const BodyView&) = delete;

  /// The deformed body (body_dataset, or a reference field with the same arrays).
  void set_body(vtkDataSet* body);
  /// Overlay lines between rows of `points` [m].
  void set_overlay(const Eigen::MatrixXd& points, const Eigen::MatrixXi& lines);
  void set_overlay_visible(bool visible);
  [[nodiscard]] bool overlay_visible() const { return m_overlay_visible; }
  /// Tool positions [m] and the force of the body on each tool [N], drawn as an arrow of length
  /// |F| x force_scale from the tool.
  void set_tools(std::span<const Eigen::Vector3d> positions, std::span<const Eigen::Vector3d> forces);
  void set_force_scale(double metres_per_newton) { m_force_scale = metres_per_newton; }
  void set_text(const std::string& text);
  /// Shows or hides the colour legend (scalar bar).
  void set_legend_visible(bool visible);
  /// Colour range [0, max] of the colouring quantity (m or Pa).
  void set_colour_range(double max);
  /// 99th percentile of the colouring quantity over the last body set's points or cells (m or Pa).
  [[nodiscard]] double data_maximum() const { return m_data_max; }
  [[nodiscard]] vtkRenderer* renderer() const { return m_renderer; }

private:
  vtkRenderer* m_renderer;
  Colouring m_colouring;
  std::vector<ToolGlyph> m_glyphs;
  double m_force_scale = 0.0;
  double m_data_max = 0.0;
  bool m_overlay_visible = true;
  vtkSmartPointer<vtkDataSetSurfaceFilter> m_surface;
  vtkSmartPointer<vtkPolyDataMapper> m_mapper;
  vtkSmartPointer<vtkLookupTable> m_lut;
  vtkSmartPointer<vtkActor> m_body;
  vtkSmartPointer<vtkPolyData> m_overlay_data;
  vtkSmartPointer<vtkActor> m_overlay;
  std::vector<vtkSmartPointer<vtkActor>> m_tools;
  std::vector<vtkSmartPointer<vtkActor>> m_arrows;
  vtkSmartPointer<vtkTextActor> m_text;
  vtkSmartPointer<vtkScalarBarActor> m_bar;
};

} // namespace kerf
