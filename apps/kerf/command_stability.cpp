// kerf stability SCENE --model M [-o DIR] [--doc FILE]: the model pushed one axis at a time past its
// nominal scene (docs/studies.md, `kerf stability`), every run classified, written as a table
// and a map (PNG, PDF); with --doc, the model's edge is written into that Markdown page.

#include "apps/kerf/commands.hpp"
#include "formats/scene/resolve_scene.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/stability_sweep.hpp"
#include "experiments/study/study_plots.hpp"
#include "experiments/study/study_table.hpp"

#include "meshes/atomic_file.hpp"

#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

namespace kerf::cli {

namespace {

struct StabilityOptions {
  std::string scene;
  std::string model;
  std::string out;
  std::string doc;
};

/// Replaces (or appends before the end marker) this scene and model's block in the page's
/// generated section, between "<!-- stability edges: begin -->" and "<!-- stability edges: end -->".
void write_edges_into(const std::filesystem::path& doc, const std::string& scene, const std::string& model,
                      const std::string& block) {
  std::ifstream in(doc);
  if (!in) throw std::runtime_error(doc.string() + ": cannot read the page to write the stability edges into");
  std::stringstream text;
  text << in.rdbuf();
  std::string page = text.str();
  const std::string end_marker = "<!-- stability edges: end -->";
  const std::string open = "<!-- stability " + scene + " " + model + " -->\n", close = "<!-- /stability " + scene + " " + model + " -->\n";
  const std::size_t end = page.find(end_marker);
  if (end == std::string::npos || page.find("<!-- stability edges: begin -->") == std::string::npos)
    throw std::runtime_error(doc.string() + ": no \"<!-- stability edges: begin -->\" … \"" + end_marker + "\" section");
  const std::size_t from = page.find(open);
  if (from != std::string::npos) {
    const std::size_t to = page.find(close, from);
    if (to == std::string::npos) throw std::runtime_error(doc.string() + ": unclosed block " + open);
    page.replace(from, to + close.size() - from, open + block + close);
  } else {
    page.insert(end, open + block + close + "\n");
  }
  write_atomically(doc, [&](const std::filesystem::path& tmp) {
    std::ofstream f(tmp);
    f << page;
    if (!f.flush()) throw std::runtime_error(doc.string() + ": write failed");
  });
}

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
  plot_stability(out / "stability_map", {{o.model, out / "stability.csv"}});
  const std::string edges = stability_edges(points);
  std::printf("%s / %s: stability sweep, %zu runs\n%s\nedges:\n%s", scene.name.c_str(), o.model.c_str(), points.size(),
              table.markdown().c_str(), edges.c_str());
  std::printf("wrote %s.{md,tex,csv} and %s.{png,pdf}\n", (out / "stability").c_str(), (out / "stability_map").c_str());
  if (!o.doc.empty()) {
    write_edges_into(o.doc, scene.name, o.model,
                     "**" + o.model + "** on `" + scene.name + "` (`kerf stability " + scene.name + " --model " + o.model +
                         " --doc " + o.doc + "`, " + std::to_string(points.size()) + " runs):\n\n" + edges);
    std::printf("wrote the edges into %s\n", o.doc.c_str());
  }
}

} // namespace

void add_stability_command(CLI::App& app) {
  auto options = std::make_shared<StabilityOptions>();
  auto* cmd = app.add_subcommand("stability", "sweep rate, stiffness, toughness, speed, Poisson ratio and mesh size "
                                              "and classify each run (bounded / oscillating / diverged / NaN / refused)");
  cmd->add_option("scene", options->scene, "scene file or name")->required();
  cmd->add_option("--model", options->model, "model name (see `kerf models`)")->required();
  cmd->add_option("-o,--output", options->out, "output directory (default runs/SCENE/MODEL/stability)");
  cmd->add_option("--doc", options->doc, "write the model's edge into this Markdown page's generated section (docs/studies.md)");
  cmd->callback([options] { run_stability(*options); });
}

} // namespace kerf::cli
