#include "experiments/study/model_resolution.hpp"

#include "experiments/models/model_catalogue.hpp"

#include <cmath>
#include <stdexcept>

namespace kerf {

std::vector<std::pair<std::string, std::string>> resolution_knobs() {
  return {{"springs", "cells per side N of the network's block"}, {"voxel", "local voxel grid cells n along its first axis"}};
}

std::pair<int, int> resolution_range(const std::string& model) {
  if (model == "springs") return {1, 64};
  if (model == "voxel") return {2, 64};
  throw std::invalid_argument("model " + model + " has no resolution a study can set (models with one: springs, voxel)");
}

ModelResolution at_resolution(const std::string& model, const Scene& scene, int value) {
  const auto [low, high] = resolution_range(model);
  if (value < low || value > high)
    throw std::invalid_argument("model " + model + ": resolution " + std::to_string(value) + " outside " + std::to_string(low) + ".." +
                                std::to_string(high));
  ModelResolution r;
  r.value = value;
  r.scene = scene;
  if (model == "springs") {
    SpringsModelSettings& s = r.scene.springs ? *r.scene.springs : r.scene.springs.emplace();
    if (s.cell_size && s.cells) s.cell_size = *s.cell_size * *s.cells / value; // the block keeps its extent
    s.cells = value;
    r.label = "springs [N = " + std::to_string(value) + "]";
    r.directory = "springs-N" + std::to_string(value);
    return r;
  }
  if (!r.scene.voxel)
    throw ModelMismatch("model voxel needs the [models.voxel] section (paper 002 Table 1) in " + scene.file.string());
  std::array<int, 3>& grid = r.scene.voxel->grid;
  const double scale = static_cast<double>(value) / grid[0];
  for (int k = 1; k < 3; ++k) grid[k] = std::max(1, static_cast<int>(std::lround(grid[k] * scale)));
  grid[0] = value;
  r.label = "voxel [grid " + std::to_string(grid[0]) + "×" + std::to_string(grid[1]) + "×" + std::to_string(grid[2]) + "]";
  r.directory = "voxel-grid" + std::to_string(value);
  return r;
}

} // namespace kerf
