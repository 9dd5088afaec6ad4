#pragma once
// How each model kerf can run (model_description.hpp: what each is and covers) is checked against
// a scene and built from it.

#include "experiments/models/model_description.hpp"
#include "formats/scene/scene.hpp"
#include "meshes/tet_mesh.hpp"
#include "meshes/vtu_writer.hpp"
#include "realtime/tool_model.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace kerf {

/// A model that cannot represent a scene: the message says what is missing.
class ModelMismatch : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// A model built for a scene, with the parameters it was built with (for the manifest).
struct BuiltModel {
  std::unique_ptr<ToolModel> model;
  nlohmann::json parameters;
  /// Optional: what the model writes into a run's directory after the last step (the edge
  /// model's cut mesh), its meshes through `write` (write_vtu); returns the entries it adds to the
  /// run's manifest. Not realtime.
  std::function<nlohmann::json(const std::filesystem::path& dir, VtuWriter write)> write_outputs = {};
  /// When `model` wraps the model proper (the springs run records the network for its .vtu
  /// series), the model proper (owned by `model`); else null. Code that looks for a concrete
  /// model type (the viewer's adapters) reads `core_model()`.
  ToolModel* core = nullptr;
  [[nodiscard]] const ToolModel& core_model() const { return core ? *core : *model; }
};

/// Checks, before any meshing, that model `name` exists and can represent `scene`: it covers
/// every phenomenon the scene declares and the scene has the tools and parameter sections the
/// model needs. Throws std::invalid_argument (unknown name) or ModelMismatch (saying what is
/// missing); returns the model's description.
const ModelDescription& require_model_for_scene(std::string_view name, const Scene& scene);

/// The phenomena of `scene` that model `name` reproduces on it (after require_model_for_scene):
/// the scene's phenomena that the model covers, less those it is admitted without on that scene —
/// the spring network on a one-blade cutting scene presses the blade's edge into the network and
/// neither cuts nor rubs (the deformation phase only, paper 000 §2.1). A study scores a model only
/// over the phases of these phenomena (study_runner.hpp). Throws as require_model_for_scene.
PhenomenonSet represented_phenomena(std::string_view name, const Scene& scene);

/// The regions of a scene's body and the fracture toughness of each: one per layer (volume group
/// names) for a layered scene, else one unnamed region (the whole mesh) with the material's J_c.
struct ToughnessRegions {
  std::vector<std::string> regions;
  std::vector<double> fracture_toughness; ///< [J/m^2]
};
ToughnessRegions toughness_regions(const Scene& scene);

/// Options a model takes from the command line (`kerf run --integrator implicit` gives
/// {"integrator": "implicit"}); a model that takes none refuses any.
using ModelOptions = std::map<std::string, std::string, std::less<>>;

/// Builds model `name` for `scene` on its mesh (after require_model_for_scene). Throws ModelMismatch when the model cannot
/// represent a phenomenon the scene declares, or lacks a tool or parameter section it needs —
/// naming what is missing — and std::invalid_argument for an unknown model name.
BuiltModel make_model(std::string_view name, const Scene& scene, const TetMesh& mesh, const ModelOptions& options = {});

} // namespace kerf
