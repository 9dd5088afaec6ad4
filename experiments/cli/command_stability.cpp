// kerf stability SCENE --model M [-o DIR]: the model pushed one axis at a time past its nominal
// scene (issue 7, "Stability at the extremes"), every run classified, written as a table.

#include "experiments/cli/commands.hpp"
#include "experiments/scene/scene_reader.hpp"
#include "experiments/study/stability_sweep.hpp"
#include "experiments/study/study_table.hpp"

#include <cstdio>
#include <memory>

namespace kerf::cli {

namespace {

struct StabilityOptions {
  std::string scene;
  std::string model;
  std::string out;
};

void run_stability(const StabilityOptions& o) {
  namespace fs = std::filesystem;
  const Scene scene = read_scene(resolve_scene(o.scene));
  const fs::path out = o.out.empty() ? fs::path("runs") / scene.name / o.model / "stability" : fs::path(o.out);
  const std::vector<StabilityPoint> points = stability_sweep(scene, o.model);
  StudyTable table({{"axis", "", 3, 1.0},
                    {"value", "", 4, 1.0},
                    {"outcome", "", 3, 1.0},
                    {"peak force", "N", 4, 1.0},
                    {"expected scale", "N", 4, 1.0},
                    {"reversing increments", "%", 3, 100.0},
                    {"note", "", 3, 1.0}});
  for (const StabilityPoint& p : points)
    table.add_row({p.axis, std::optional<double>(p.value), std::string(to_string(p.outcome)),
                   p.outcome == StabilityClass::refused ? std::optional<double>() : std::optional<double>(p.peak_force),
                   std::optional<double>(p.expected_scale),
                   p.outcome == StabilityClass::refused ? std::optional<double>() : std::optional<double>(p.reversal_fraction),
                   p.note});
  table.write(out, "stability");
  std::printf("%s / %s: stability sweep, %zu runs\n%s", scene.name.c_str(), o.model.c_str(), points.size(),
              table.markdown().c_str());
  std::printf("wrote %s.{md,tex,csv}\n", (out / "stability").c_str());
}

} // namespace

void add_stability_command(CLI::App& app) {
  auto options = std::make_shared<StabilityOptions>();
  auto* cmd = app.add_subcommand("stability", "sweep rate, stiffness, toughness, speed, Poisson ratio and mesh size "
                                              "and classify each run (bounded / oscillating / diverged / NaN / refused)");
  cmd->add_option("scene", options->scene, "scene file or name")->required();
  cmd->add_option("--model", options->model, "model name (see `kerf models`)")->required();
  cmd->add_option("-o,--output", options->out, "output directory (default runs/SCENE/MODEL/stability)");
  cmd->callback([options] { run_stability(*options); });
}

} // namespace kerf::cli
