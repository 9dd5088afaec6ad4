#pragma once
// Replay of recorded runs side by side (`kerf view RUN_DIR [RUN_DIR...]`): one view per run
// directory (kerf run or kerf reference output: manifest.json + profile.csv, and for the
// reference fields.pvd), all at one time chosen by a shared slider, coloured by displacement or
// von Mises stress, above a chart of each run's force-displacement curve with a marker at that
// time. A reference run shows its fields; a fast model's run is re-stepped through the tool
// positions its profile recorded (the models are deterministic) and shows the model's own
// geometry (the embedded fine mesh of the spring network, the voxel model's surface, ...).

#include "viewer/body_view.hpp"
#include "viewer/view_window.hpp"

#include <filesystem>
#include <vector>

namespace kerf {

struct ReplaySettings {
  std::vector<std::filesystem::path> runs;  ///< run directories, shown left to right
  Colouring colouring = Colouring::displacement;
  double colour_max = 0.0;                  ///< 0: the largest value over all runs at the shown time
  CameraView camera = CameraView::oblique;
  bool overlay = true;
  bool text = true;                         ///< the text blocks and colour legends
  bool chart = true;                        ///< the force-displacement chart below the views
  ViewWindowSettings window;
  int frames = 100;                         ///< fast model: snapshots over the run (the slider snaps to the nearest)
  std::filesystem::path screenshot;         ///< off screen: write this PNG at `at` and return
  double at = -1.0;                         ///< time of the screenshot [s]; < 0: the end of the longest run
};

/// Loads the runs (std::runtime_error naming the directory and what is missing), then either
/// writes the screenshot or opens the window (slider drags the time; space plays/pauses; o
/// toggles the overlay) until it is closed.
void replay_runs(const ReplaySettings& settings);

} // namespace kerf
