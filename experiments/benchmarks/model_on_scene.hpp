#pragma once
// A fast model built on a repository scene and stepped along the scene's own trajectory, for the
// step-cost benchmarks (bench_fracture_step.cpp, bench_voxel_step.cpp).

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"

#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>
#include <vector>

namespace kerf::bench {

struct ModelOnScene {
  Scene scene;
  TetMesh mesh;
  BuiltModel model;
  std::vector<ToolState> samples; ///< the first tool's trajectory at 1 kHz
};

/// Model `model` on experiments/scenes/SCENE.toml, meshed at `element_size` [m] (0: the scene's).
inline ModelOnScene model_on_scene(const std::string& model, const std::string& scene, double element_size) {
  ModelOnScene f;
  f.scene = read_scene(std::filesystem::path(KERF_SOURCE_DIR) / "experiments/scenes" / (scene + ".toml"));
  if (element_size > 0.0) f.scene.geometry.element_size = element_size;
  f.mesh = scene_mesh(f.scene);
  f.model = make_model(model, f.scene, f.mesh);
  f.samples = sample(f.scene.tools.front().trajectory).samples;
  return f;
}

/// One model step (1 ms) per benchmark iteration, through the trajectory and again from a reset
/// model, so every mode of the scene is in the mix; counts the steps per second.
inline void step_along_trajectory(benchmark::State& state, ModelOnScene& f) {
  ForceSample out;
  std::size_t k = 0;
  for (auto _ : state) {
    if (k == f.samples.size()) {
      k = 0;
      f.model.model->reset();
    }
    f.model.model->step({&f.samples[k++], 1}, 1e-3, {&out, 1});
    benchmark::DoNotOptimize(out);
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

} // namespace kerf::bench
