#pragma once
// The viewer's reading of SpringNetworkModel (paper 000 §2): the fine mesh moved by the network
// through a 3-D Coons embedding (§2.1), split along the network's pieces once it tears (§2.2,
// Fig. 5), and the network's cell edges as the overlay.

#include "realtime/springs/network_embedding.hpp"
#include "realtime/springs/spring_network_model.hpp"
#include "viewer/model_adapter.hpp"

#include <memory>

namespace kerf {

/// ModelState layout: points/rest = network node positions/rest positions (3 x node capacity),
/// cells = each cell's 8 nodes, topology = the model's tear count, scalars[0] = tears,
/// scalars[1] = pieces.
class SpringsAdapter final : public ModelAdapter {
public:
  /// `model` must still be untorn (built, not yet stepped through a tear); `mesh` is the scene
  /// mesh it was built on.
  SpringsAdapter(const SpringNetworkModel& model, const TetMesh& mesh);

  void reserve(ModelState& state) const override;
  void capture(ModelState& state) const noexcept override;
  void geometry(const ViewFrame& frame, BodyGeometry& out) override;
  [[nodiscard]] std::string_view overlay_name() const override { return "spring network"; }

private:
  void rebuild_body(const ModelState& state);

  const SpringNetworkModel& m_model;
  TetMesh m_mesh;
  SpringNetwork m_net;                       ///< the render thread's copy, re-pointed as the model tears
  TetMesh m_body;                            ///< the fine mesh as drawn (split once torn)
  std::unique_ptr<NetworkEmbedding> m_embedding;
  std::uint64_t m_topology = 0;
  Eigen::Matrix3Xd m_x;                      ///< network positions, node capacity columns
};

} // namespace kerf
