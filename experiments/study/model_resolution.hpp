#pragma once
// A fast model at another resolution (one point of its speed/accuracy trade each): a study file's
// `[models.NAME] resolutions = [...]` runs the model once per value, each a point of its
// speed/accuracy curve. The knob of each model, set on the scene the model is built from (its
// builder reads it there; experiments/models/*_builder.cpp):
//
//   springs   N, the cells per side of the network's block (paper 000 §2.1; [models.springs] cells).
//             A scene that fixes the cell size too keeps the block's extent: cell size × N stays.
//   voxel     n, the local voxel grid's cells along its first axis (paper 002 §4: 10 × 20 × 20);
//             the other two scale with it (n × 2n × 2n for the paper's proportions).
//
// The other models have no resolution a study can set without changing their builders: the edge
// model's voxel size is a quarter of the scene's element size (edge_builder.cpp), the fracture model
// has none of its own.

#include "formats/scene/scene.hpp"

#include <string>
#include <vector>

namespace kerf {

/// One point of a model's resolution sweep.
struct ModelResolution {
  int value = 0;
  std::string label;     ///< the table's model column: "springs [N = 4]", "voxel [grid 5×10×10]"
  std::string directory; ///< the run's directory name under the scene: "springs-N4", "voxel-grid5"
  Scene scene;           ///< the scene with the knob set
};

/// The models a study can sweep and what their knob is, e.g. {"springs", "cells per side N"}.
std::vector<std::pair<std::string, std::string>> resolution_knobs();

/// The valid range of `model`'s knob: [1, 64] for springs, [2, 64] for voxel. Throws
/// std::invalid_argument for a model without a knob.
std::pair<int, int> resolution_range(const std::string& model);

/// `model` on `scene` at resolution `value`. Throws std::invalid_argument for a model without a
/// knob or a value out of its range; ModelMismatch (model_catalogue.hpp) for a voxel resolution on
/// a scene without [models.voxel] (the run would refuse it anyway).
ModelResolution at_resolution(const std::string& model, const Scene& scene, int value);

} // namespace kerf
