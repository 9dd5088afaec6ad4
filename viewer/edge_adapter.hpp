#pragma once
// The viewer's reading of DiscreteEdgeCuttingModel (paper 000 §3.1): the body at rest (this model
// renders force; its geometric cut, §3.2, is a separate offline step), the discretised edge's
// present points and, for each point that has cut, its cut path from the entry point to its
// relaxed position, as the overlay.

#include "realtime/edge/discrete_edge_cutting_model.hpp"
#include "viewer/model_adapter.hpp"

namespace kerf {

/// ModelState layout (n edge points): points [0, n) present positions p_i, [n, 2n) entry points,
/// [2n, 3n) relaxed positions r_i [m]; scalars[0] = points that have cut.
class EdgeAdapter final : public ModelAdapter {
public:
  EdgeAdapter(const DiscreteEdgeCuttingModel& model, const TetMesh& mesh);

  void reserve(ModelState& state) const override;
  void capture(ModelState& state) const noexcept override;
  void geometry(const ViewFrame& frame, BodyGeometry& out) override;
  [[nodiscard]] std::string_view overlay_name() const override { return "discrete edge"; }

private:
  const DiscreteEdgeCuttingModel& m_model;
  TetMesh m_mesh;
  std::vector<std::uint8_t> m_cut; ///< render thread: which points have cut (from rest vs entry)
};

} // namespace kerf
