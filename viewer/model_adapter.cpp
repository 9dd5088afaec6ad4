#include "viewer/model_adapter.hpp"

#include "viewer/edge_adapter.hpp"
#include "viewer/fracture_adapter.hpp"
#include "viewer/shape_forming_adapter.hpp"
#include "viewer/springs_adapter.hpp"
#include "viewer/voxel_adapter.hpp"

namespace kerf {

namespace {

/// A model the viewer has no adapter for: its scene mesh at rest, no overlay.
class RestBodyAdapter final : public ModelAdapter {
public:
  RestBodyAdapter(const ToolModel& model, const TetMesh& mesh) : m_name(model.name()), m_mesh(mesh) {}
  void reserve(ModelState& state) const override {
    state.points.resize(3, 0);
    state.rest.resize(3, 0);
    state.cells.clear();
  }
  void capture(ModelState&) const noexcept override {}
  void geometry(const ViewFrame&, BodyGeometry& out) override {
    out.points = m_mesh.nodes;
    out.rest = m_mesh.nodes;
    out.tets = m_mesh.tets;
    out.triangles.resize(0, 3);
    out.overlay_points.resize(0, 3);
    out.overlay_lines.resize(0, 2);
    out.status = m_name + ": body at rest (no geometry adapter)";
  }
  [[nodiscard]] std::string_view overlay_name() const override { return "none"; }

private:
  std::string m_name;
  TetMesh m_mesh;
};

} // namespace

std::unique_ptr<ModelAdapter> make_model_adapter(const ToolModel& model, const TetMesh& mesh) {
  if (const auto* m = dynamic_cast<const SpringNetworkModel*>(&model)) return std::make_unique<SpringsAdapter>(*m, mesh);
  if (const auto* m = dynamic_cast<const VoxelSurfaceCuttingModel*>(&model)) return std::make_unique<VoxelAdapter>(*m, mesh);
  if (const auto* m = dynamic_cast<const FractureCuttingModel*>(&model)) return std::make_unique<FractureAdapter>(*m, mesh);
  if (const auto* m = dynamic_cast<const DiscreteEdgeCuttingModel*>(&model)) return std::make_unique<EdgeAdapter>(*m, mesh);
  if (const auto* m = dynamic_cast<const ShapeFormingModel*>(&model)) return std::make_unique<ShapeFormingAdapter>(*m, mesh);
  return std::make_unique<RestBodyAdapter>(model, mesh);
}

std::unique_ptr<ModelAdapter> make_model_adapter(const BuiltModel& built, const TetMesh& mesh) {
  return make_model_adapter(built.core_model(), mesh);
}

} // namespace kerf
