#pragma once
// ModelAdapter: how the viewer reads one model type's geometry through the model's public
// accessors (the models live in realtime/ and know nothing of the viewer). Three steps with three
// threading rules:
//   reserve  — before the session, sizes a ModelState for everything the model can reach (allocates);
//   capture  — in the thread that steps the model, right after a step: copies numbers into the
//              reserved ModelState (allocation-free, lock-free, bounded: the servo's rules);
//   geometry — in the render thread, turns a captured ViewFrame into BodyGeometry (allocates).

#include "experiments/models/model_catalogue.hpp"
#include "meshes/tet_mesh.hpp"
#include "realtime/tool_model.hpp"
#include "viewer/body_geometry.hpp"
#include "viewer/view_frame.hpp"

#include <memory>
#include <string_view>

namespace kerf {

class ModelAdapter {
public:
  virtual ~ModelAdapter() = default;
  /// Sizes `state` for the whole session. Allocates; call before the model's thread starts.
  virtual void reserve(ModelState& state) const = 0;
  /// Copies the model's geometry-bearing state into `state` (sized by reserve). Called in the
  /// model's thread between steps; allocation-free.
  virtual void capture(ModelState& state) const noexcept = 0;
  /// The body as `frame` (its ModelState and force samples) describes it (render thread;
  /// allocates). A frame with nothing captured yet (point_count 0) gives the rest body.
  virtual void geometry(const ViewFrame& frame, BodyGeometry& out) = 0;
  /// What the overlay shows ("spring network", "voxel grid", ...).
  [[nodiscard]] virtual std::string_view overlay_name() const = 0;
};

/// The adapter for `model` (springs, voxel, fracture, edge, and edge's shape forming on a blade
/// and a stylus; recognised by its dynamic type),
/// built on `mesh`, the scene mesh the model was built from. A model type without an adapter
/// gets the rest mesh and no overlay (the tools, forces and text are drawn for every model).
std::unique_ptr<ModelAdapter> make_model_adapter(const ToolModel& model, const TetMesh& mesh);

/// The adapter for a model from the catalogue (make_model): it reads the model proper,
/// `built.core_model()`, which a builder may wrap for `kerf run`'s own recording (the springs
/// run's .vtu series); the wrapper is what is stepped, the model proper what is read.
std::unique_ptr<ModelAdapter> make_model_adapter(const BuiltModel& built, const TetMesh& mesh);

} // namespace kerf
