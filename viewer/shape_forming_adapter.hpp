#pragma once
// The viewer's reading of ShapeFormingModel (paper 000 §4: cutting and deforming on one fine
// model): before the geometric cut reaches the servo thread, the body at rest and the blade's
// discretised edge (§3.1); from then on the body as the cut left it (§3.2: its fragments) with
// the fragment under the stylus moved by its spring network through the stage's embedding (§2.1),
// and that network's cell edges beside the edge as the overlay.

#include "realtime/edge/shape_forming_model.hpp"
#include "viewer/model_adapter.hpp"

namespace kerf {

/// ModelState layout (m network nodes, n edge points): points [0, m) the active stage's network
/// node positions and rest [0, m) their rest positions [m], cells the network's cells (corner
/// nodes), points [m, m + n) the edge's present points p_i [m]; published = the active
/// FormingStage (null before the first cut is applied), topology = its address; scalars[0] =
/// edge points that have cut, scalars[1] = m, scalars[2] = n.
///
/// Threads: capture reads the model's active stage and its network in the thread that steps
/// them. The render thread reads only what never changes once the stage is published (the cut
/// body's copy, the fragment's node map and embedding, the network's grid indices, written when
/// the network is built) and the captured numbers; the cells' corners come from the capture.
class ShapeFormingAdapter final : public ModelAdapter {
public:
  ShapeFormingAdapter(const ShapeFormingModel& model, const TetMesh& mesh);

  void reserve(ModelState& state) const override;
  void capture(ModelState& state) const noexcept override;
  void geometry(const ViewFrame& frame, BodyGeometry& out) override;
  [[nodiscard]] std::string_view overlay_name() const override { return "discrete edge, spring network"; }

private:
  const ShapeFormingModel& m_model;
  TetMesh m_mesh;
  // Render thread: the stage drawn last and its network's copy (grid from the stage, corners
  // from each frame).
  const FormingStage* m_stage = nullptr;
  SpringNetwork m_net;
  Eigen::Matrix3Xd m_x;
  Eigen::MatrixXd m_moved;
  int m_fragments = 0;
};

} // namespace kerf
