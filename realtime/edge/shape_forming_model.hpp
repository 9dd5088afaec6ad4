#pragma once
// ShapeFormingModel: paper 000 §4 ("Application to Shape Forming Task") — cutting and deforming
// on one shared fine TetMesh. A blade cuts the body with the discrete-edge model (§3.1) and the
// geometric cut (§3.2, off the servo thread); then a stylus deforms the fragment it touches with
// the spring network (§2), built on that fragment's tetrahedra as the cut left them: "by sharing a
// geometric model in both cutting and deforming operations, it became possible to switch these
// two operations without transforming the internal representation of the object" (§5).

#include "meshes/tet_mesh.hpp"
#include "realtime/edge/discrete_edge_cutting_model.hpp"
#include "realtime/springs/network_embedding.hpp"
#include "realtime/springs/spring_network_model.hpp"
#include "realtime/tool_model.hpp"

#include <atomic>
#include <memory>
#include <vector>

namespace kerf {

/// Everything the model is built from (SI units).
struct ShapeFormingSetup {
  DiscreteEdgeSetup edge;                 ///< the blade (tool 0), paper 000 §3.1
  double voxel_size = 0.0;                ///< collision voxels of §3.3 [m] > 0
  std::vector<std::string> regions;       ///< volume groups of the edge materials (empty: one)
  GeometricCutOptions cut;                ///< §3.2 tolerances
  double record_spacing = 0.0;            ///< trajectory recording spacing [m] > 0
  SpringNetworkSetup springs;             ///< the spring network with exactly one stylus (tool 1)
  /// Offline runs replay a trajectory faster than real time; when true, `step` waits (spinning on
  /// the hand-over's atomic state: no lock, no allocation, but unbounded time) until a handed-over
  /// cut is applied, so the profile does not depend on the worker's speed. Must be false in a
  /// servo loop: there the stylus phase begins at the first sample after the cut is published.
  bool wait_for_cut = false;
};

/// One fragment made deformable: its tetrahedra (a compacted copy of the cut mesh's), the spring
/// network built on them and the embedding of their nodes. Built on the cut's worker thread,
/// never changed after it is published (only its spring model is stepped, by the servo thread).
struct FormingStage {
  int fragment = -1;                      ///< fragment index in the cut body
  TetMesh mesh;                           ///< the fragment's tetrahedra and nodes
  std::vector<int> cut_mesh_node;         ///< node of the cut mesh for each node of `mesh`
  /// The whole body as this cut left it (a copy of the CuttableBody's mesh and fragment labels
  /// when the stage was built): what a reader outside the worker thread (the viewer) may read
  /// once it holds the published stage, while the worker's own body may change with a later cut.
  TetMesh cut_mesh;
  std::vector<int> fragment_of_tet;       ///< fragment of each tetrahedron of `cut_mesh`
  std::unique_ptr<SpringNetworkModel> springs;
  std::unique_ptr<NetworkEmbedding> embedding;
};

/// Tools: 0 the blade, 1 the stylus. `step`: the blade gets the discrete-edge force (§3.1); its
/// passes are cut off the servo thread (DiscreteEdgeCuttingModel::attach_geometric_cut). After
/// each cut the worker picks the fragment nearest to the stylus's start (the tetrahedron whose
/// centroid is closest), copies its tetrahedra with their nodes and surface groups (the boundary
/// faces of the fragment lying on a group's original triangles), builds the spring network on it
/// (SpringNetworkModel, the stylus grasping it at its start) and the trilinear embedding of its
/// nodes, and publishes the stage with one atomic pointer store (release). The servo thread loads
/// the pointer (acquire) each step; from the first step that sees a stage the stylus gets that
/// network's force, before it none (no-contact). A later cut publishes a new stage (the network
/// is rebuilt on the new fragment). Stages are freed only by reset() or destruction.
class ShapeFormingModel final : public ToolModel {
public:
  /// Throws std::invalid_argument on a bad setup (not exactly one stylus, bad edge parameters).
  ShapeFormingModel(const TetMesh& mesh, ShapeFormingSetup setup);
  ~ShapeFormingModel() override;

  /// "edge": the command-line model that builds it for a scene with a blade and a stylus.
  [[nodiscard]] std::string_view name() const override { return "edge"; }
  [[nodiscard]] int tool_count() const override { return 2; }
  void reset() override;
  void step(std::span<const ToolState> tools, double dt, std::span<ForceSample> forces) noexcept override;

  [[nodiscard]] DiscreteEdgeCuttingModel& edge() { return *m_edge; }
  [[nodiscard]] const DiscreteEdgeCuttingModel& edge() const { return *m_edge; }
  [[nodiscard]] const ShapeFormingSetup& setup() const { return m_setup; }
  /// The stage the stylus is deforming (null before the first cut reached the servo thread).
  [[nodiscard]] const FormingStage* active_stage() const { return m_active; }
  /// Not realtime: the cut mesh with the active fragment's nodes moved by the network
  /// (embedding); every other node where the cut left it. Call when no step runs.
  [[nodiscard]] TetMesh formed_mesh();

private:
  void build_stage(const CuttableBody& body);

  ShapeFormingSetup m_setup;
  std::unique_ptr<DiscreteEdgeCuttingModel> m_edge;
  std::vector<std::unique_ptr<FormingStage>> m_stages; ///< owned by the worker while it runs
  std::atomic<FormingStage*> m_published{nullptr};
  FormingStage* m_active = nullptr; ///< servo thread's
};

/// The fragment `fragment` of `body` as a mesh of its own: its tetrahedra, its nodes (compacted;
/// `cut_mesh_node` receives the body's node of each), its volume groups, and each surface group
/// of the body's mesh as the fragment's boundary faces whose three nodes lie on that group's
/// triangles (within 1e-9 of the body's size; the cut leaves a group's original triangles in
/// place, paper 000 §3.2 divides only tetrahedra).
TetMesh fragment_mesh(const CuttableBody& body, int fragment, std::vector<int>& cut_mesh_node);

} // namespace kerf
