#pragma once
// The viewer's reading of FractureCuttingModel (paper 001): the body does not move in that model
// (its deformation is an energy, not a shape), so the fine mesh is drawn at rest and the crack —
// the plane the blade has opened from its entry point to the crack depth c (Fig. 3) — is the
// overlay.

#include "realtime/fracture/fracture_cutting_model.hpp"
#include "viewer/model_adapter.hpp"

namespace kerf {

/// ModelState layout: scalars[0..2] = the cutting frame's origin (the entry point) [m],
/// scalars[3] = 1 once the blade has touched the body. The crack depth is the force sample's
/// crack_extent.
class FractureAdapter final : public ModelAdapter {
public:
  FractureAdapter(const FractureCuttingModel& model, const TetMesh& mesh);

  void reserve(ModelState& state) const override;
  void capture(ModelState& state) const noexcept override;
  void geometry(const ViewFrame& frame, BodyGeometry& out) override;
  [[nodiscard]] std::string_view overlay_name() const override { return "crack"; }

private:
  const FractureCuttingModel& m_model;
  TetMesh m_mesh;
};

} // namespace kerf
