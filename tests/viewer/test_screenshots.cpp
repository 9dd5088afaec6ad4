// `kerf view ... --screenshot` under Xvfb (xvfb_display.cpp): pictures of runs (`kerf run`, then
// `kerf view RUN_DIR --at T`) checked against what the scene says must be seen. Front camera
// (parallel projection, x to the right, z up), no text, legend or chart, fixed colour scale, so a
// pixel changes only where the body, a tool or a force changes. The image is mapped to world x
// and z from the body's own silhouette at t = 0 (the block's known extent in the scene file),
// never from the renderer's internals.

#include "tests/viewer/png_image.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <utility>
#include <vector>

using kerf::test::PngImage;

namespace {

std::filesystem::path scratch_dir() {
  return std::filesystem::temp_directory_path() / ("kerf_test_viewer_" + std::to_string(::getpid()));
}

std::filesystem::path scratch(const std::string& name) {
  std::filesystem::create_directories(scratch_dir());
  return scratch_dir() / name;
}

/// Removes the runs and pictures when every test passed (kept for a look when one failed).
class ScratchCleanup : public ::testing::Environment {
public:
  void TearDown() override {
    if (::testing::UnitTest::GetInstance()->Passed()) std::filesystem::remove_all(scratch_dir());
  }
};
[[maybe_unused]] const ::testing::Environment* const cleanup = ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

/// Runs kerf with `arguments`; returns its exit code and standard output.
std::pair<int, std::string> run_kerf(const std::string& arguments) {
  const std::string command = std::string(KERF_BINARY) + " " + arguments + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return {-1, ""};
  std::string out;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe)) out += buffer.data();
  const int status = ::pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

/// World x [m] and z [m] of the block's silhouette in the t = 0 picture: its leftmost and
/// rightmost foreground columns are x = 0 and x = length, its lowest foreground row is z = 0.
struct ImageFrame {
  int left = 0, right = 0, bottom = 0;
  double pixels_per_metre = 0.0;
  [[nodiscard]] int column(double x) const { return left + static_cast<int>(std::lround(x * pixels_per_metre)); }
  [[nodiscard]] int row(double z) const { return bottom + static_cast<int>(std::lround(z * pixels_per_metre)); }
  [[nodiscard]] double x(int column) const { return (column - left) / pixels_per_metre; }
};

ImageFrame locate_block(const PngImage& rest, double length) {
  ImageFrame f;
  f.left = rest.width;
  f.right = -1;
  f.bottom = rest.height;
  for (int y = 0; y < rest.height; ++y)
    for (int x = 0; x < rest.width; ++x)
      if (rest.foreground(x, y)) {
        f.left = std::min(f.left, x);
        f.right = std::max(f.right, x);
        f.bottom = std::min(f.bottom, y);
      }
  f.pixels_per_metre = (f.right - f.left) / length;
  return f;
}

const std::string picture = " --camera front --no-text --no-chart --width 800 --height 600";

} // namespace

// clay_pull (experiments/scenes/clay_pull.toml): a 40 x 40 x 20 mm block, the stylus pulls the
// top centre (x = 20 mm) up 6 mm in 1.6 s. The spring network is built around the stylus only
// (8 cells of 2.5 mm: x in [10, 30] mm, spring_network_model.hpp) and fine nodes outside it keep
// their rest positions (paper 000 §2.1, network_embedding.hpp): outside the network, widened by
// one element (2.5 mm, the scene's element size) whose colour interpolates from a moved node,
// nothing may change; above the pulled surface, the body and the moved stylus must.
TEST(ViewerScreenshot, ClayPullChangesOnlyWhereTheBodyDeforms) {
  const auto run = scratch("clay_pull_springs");
  auto [code, out] = run_kerf("run clay_pull --model springs -o " + run.string());
  ASSERT_EQ(code, 0) << out;
  const auto before = scratch("clay_pull_0.png"), after = scratch("clay_pull_1.6.png");
  const std::string common = "view " + run.string() + " --colour-max \"8 mm\"" + picture;
  auto [code0, out0] = run_kerf(common + " --screenshot " + before.string() + " --at 0");
  ASSERT_EQ(code0, 0) << out0;
  auto [code1, out1] = run_kerf(common + " --screenshot " + after.string() + " --at 1.6");
  ASSERT_EQ(code1, 0) << out1;
  const PngImage a = PngImage::read(before), b = PngImage::read(after);
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);

  const ImageFrame f = locate_block(a, 0.040);
  ASSERT_GT(f.pixels_per_metre, 5000.0) << "the block should span a good part of the 800 px picture";
  // The silhouette's height is the block's 20 mm (a parallel front projection, square pixels).
  int top = f.bottom;
  for (int y = f.bottom; y < a.height; ++y)
    if (a.foreground(f.column(0.005), y)) top = y;
  EXPECT_NEAR((top - f.bottom + 1) / f.pixels_per_metre, 0.020, 2.0 / f.pixels_per_metre + 1e-4);

  // Elsewhere: every pixel left of x = 7 mm and right of x = 33 mm, body and background alike.
  long elsewhere = 0, changed_elsewhere = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const double wx = f.x(x);
      if (wx < 0.007 || wx > 0.033) {
        ++elsewhere;
        if (a.difference(b, x, y) != 0) ++changed_elsewhere;
      }
    }
  EXPECT_GT(elsewhere, 100000);
  EXPECT_EQ(changed_elsewhere, 0) << "pixels changed away from the deformed region";

  // The deformed region: where the surface under the stylus was pulled up, above the rest top
  // (z = 20 mm) between x = 15 and 25 mm. (The block's front face, y = -20 mm, lies outside the
  // network, which spans y in [-10, 10] mm, so it rightly does not change.)
  long region = 0, changed = 0;
  for (int y = f.row(0.0205); y <= f.row(0.029); ++y)
    for (int x = f.column(0.015); x <= f.column(0.025); ++x) {
      ++region;
      if (a.difference(b, x, y) > 8) ++changed;
    }
  EXPECT_GT(changed, region / 2) << changed << " of " << region << " pixels changed above the pulled surface";
  // And the body's top follows the stylus: at x = 20 mm (just beside the tool's axis the sphere
  // does not cover) foreground reaches well above the rest top (z = 20 mm) at 1.6 s.
  int rest_top = 0, pulled_top = 0;
  const int column = f.column(0.0175);
  for (int y = 0; y < a.height; ++y) {
    if (a.foreground(column, y)) rest_top = y;
    if (b.foreground(column, y)) pulled_top = y;
  }
  EXPECT_GT(pulled_top - rest_top, static_cast<int>(0.002 * f.pixels_per_metre));
}

// clay_tear (experiments/scenes/clay_tear.toml): a 60 x 20 x 20 mm block pulled apart at x = 15
// and 45 mm by 10 mm each; the network (cells of h = 5 mm, [models.springs]) tears where the
// tensile stress passes the cohesive strength, along cell faces (vertex splitting), the expected
// tear surface being the mid-plane x = 30 mm. Fragments along the pulling direction: the
// picture's columns that hold foreground within the block's height (z in [1, 19] mm), in runs. At
// rest one run; torn and pulled apart two, separated by a gap of empty columns centred within
// 1.5 cells (7.5 mm) of the mid-plane (this model tears at the face x = 35 mm: the gap's centre
// in the rest frame is the tear's position). The gap is as wide as the pieces moved apart: each
// follows its stylus, 10 mm out at t = 3 s (the scene's trajectories: 10 mm at 5 mm/s, then a
// 1 s hold in which the pieces' recoil is damped out), 20 mm in all for a plane tear, down to
// 15 mm if the tear steps by one cell across the section; never wider than 20 mm, up to one
// pixel at each side of the gap (silhouette rasterisation). (A series read with its moved points
// moved by the displacement again showed 27.6 mm: each piece 20 mm out, and spikes back to the
// tear from nodes the series had left at rest.)
TEST(ViewerScreenshot, TornClayShowsTwoFragmentsAlongTheTearLine) {
  const auto run = scratch("clay_tear_springs");
  auto [code, out] = run_kerf("run clay_tear --model springs -o " + run.string());
  ASSERT_EQ(code, 0) << out;
  {
    // The model marks the sample at which a tear separates the network "rupture" (springs model;
    // tests/realtime/springs/test_tearing.cpp: clay_tear tears). Without a tear there would be
    // no fragments to see, and the pictures below would test nothing.
    std::ifstream profile(run / "profile.csv");
    const std::string text((std::istreambuf_iterator<char>(profile)), std::istreambuf_iterator<char>());
    ASSERT_NE(text.find(",rupture,"), std::string::npos) << "the springs model did not tear clay_tear";
  }
  const auto before = scratch("clay_tear_0.png"), after = scratch("clay_tear_end.png");
  const std::string common = "view " + run.string() + picture;
  auto [code0, out0] = run_kerf(common + " --screenshot " + before.string() + " --at 0");
  ASSERT_EQ(code0, 0) << out0;
  auto [code1, out1] = run_kerf(common + " --screenshot " + after.string() + " --at 3");
  ASSERT_EQ(code1, 0) << out1;
  const PngImage a = PngImage::read(before), b = PngImage::read(after);
  const ImageFrame f = locate_block(a, 0.060);
  ASSERT_GT(f.pixels_per_metre, 5000.0);
  auto fragments = [&](const PngImage& image, std::vector<std::pair<int, int>>* runs) {
    std::vector<bool> occupied(static_cast<std::size_t>(image.width), false);
    for (int x = 0; x < image.width; ++x)
      for (int y = f.row(0.001); y <= f.row(0.019); ++y)
        if (image.foreground(x, y)) occupied[static_cast<std::size_t>(x)] = true;
    int count = 0;
    for (int x = 0; x < image.width; ++x)
      if (occupied[static_cast<std::size_t>(x)] && (x == 0 || !occupied[static_cast<std::size_t>(x - 1)])) {
        ++count;
        int end = x;
        while (end + 1 < image.width && occupied[static_cast<std::size_t>(end + 1)]) ++end;
        if (runs) runs->emplace_back(x, end);
      }
    return count;
  };
  EXPECT_EQ(fragments(a, nullptr), 1);
  std::vector<std::pair<int, int>> runs;
  ASSERT_EQ(fragments(b, &runs), 2) << "the torn block should show two fragments";
  const double gap_centre = f.x((runs[0].second + runs[1].first) / 2);
  EXPECT_NEAR(gap_centre, 0.030, 0.0075) << "the gap should lie on the tear line x = 30 mm";
  const double gap_width = (runs[1].first - runs[0].second - 1) / f.pixels_per_metre;
  EXPECT_GT(gap_width, 0.015) << "the pieces should be 20 mm apart";
  EXPECT_LE(gap_width, 0.020 + 2.0 / f.pixels_per_metre) << "the pieces should be 20 mm apart";
}

// clay_cut_apart (experiments/scenes/clay_cut_apart.toml): a 30 x 10 x 10 mm clay bar resting on
// a smooth plate (sliding support); a blade goes down through its full depth at x = 10 mm (1.2 s
// at 10 mm/s) and clears below the base; from 1.8 s a stylus on the cube's top drags it 5 mm
// along -x (1 s at 5 mm/s), then holds 1 s. Model `edge` (shape forming, paper 000 §4): the
// geometric cut (§3.2) divides the mesh along its internal plane x = 10 mm into a 10 mm cube and
// a 20 mm bar (the run's manifest: 2 fragments); the spring network built on the cube's fragment
// (8 cells of 1.25 mm: the whole cube, nothing of it held but its base's height) carries it with
// the stylus; the bar is in no network and keeps its nodes where the cut left them.
// Where the separation comes from: the cut has no width (the blade's thickness is not removed,
// the crack's node copies start where the nodes were), so after the cut and before the drag the
// two pieces touch: one component. At the end the cube has moved with the stylus, 5 mm: the gap
// is the stylus's travel, between the cube's cut face (10 - 5 mm) and the bar's (10 mm). Checked
// in the band z in [1, 9] mm across the picture ("along the cut line", clear of the stylus above
// the top and of the blade below the base): the 4-connected components of foreground pixels,
// each with its column extent; the gap is measured between the two components' facing columns,
// one pixel of silhouette rasterisation allowed at each side.
TEST(ViewerScreenshot, CutClayShowsTwoFragmentsOnceThePieceIsDraggedAway) {
  const auto run = scratch("clay_cut_apart_edge");
  auto [code, out] = run_kerf("run clay_cut_apart --model edge -o " + run.string());
  ASSERT_EQ(code, 0) << out;
  {
    // The model itself cut the bar through: its manifest counts two fragments (edge_builder.cpp,
    // write_geometric_cut). Without that there would be nothing to separate.
    std::ifstream manifest(run / "manifest.json");
    const std::string text((std::istreambuf_iterator<char>(manifest)), std::istreambuf_iterator<char>());
    ASSERT_NE(text.find("\"fragments\": 2"), std::string::npos) << "the edge model did not cut clay_cut_apart in two";
  }
  const auto rest = scratch("clay_cut_apart_0.png"), cut = scratch("clay_cut_apart_1.75.png"),
             apart = scratch("clay_cut_apart_end.png");
  const std::string common = "view " + run.string() + picture;
  for (const auto& [file, at] : {std::pair{rest, "0"}, std::pair{cut, "1.75"}, std::pair{apart, "3.8"}}) {
    auto [c, o] = run_kerf(common + " --screenshot " + file.string() + " --at " + at);
    ASSERT_EQ(c, 0) << o;
  }
  const PngImage a = PngImage::read(rest), b = PngImage::read(cut), c = PngImage::read(apart);
  const ImageFrame f = locate_block(a, 0.030);
  ASSERT_GT(f.pixels_per_metre, 5000.0);
  // 4-connected components of foreground in the band; their column extents, left to right.
  auto components = [&](const PngImage& image) {
    const int y0 = f.row(0.001), y1 = f.row(0.009);
    const int rows = y1 - y0 + 1;
    std::vector<int> label(static_cast<std::size_t>(rows) * image.width, -1);
    std::vector<std::pair<int, int>> extents;
    for (int y = y0; y <= y1; ++y)
      for (int x = 0; x < image.width; ++x) {
        if (!image.foreground(x, y) || label[static_cast<std::size_t>(y - y0) * image.width + x] >= 0) continue;
        const int id = static_cast<int>(extents.size());
        extents.emplace_back(x, x);
        std::vector<std::pair<int, int>> stack{{x, y}};
        label[static_cast<std::size_t>(y - y0) * image.width + x] = id;
        while (!stack.empty()) {
          const auto [px, py] = stack.back();
          stack.pop_back();
          extents[static_cast<std::size_t>(id)].first = std::min(extents[static_cast<std::size_t>(id)].first, px);
          extents[static_cast<std::size_t>(id)].second = std::max(extents[static_cast<std::size_t>(id)].second, px);
          for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
            const int nx = px + dx, ny = py + dy;
            if (nx < 0 || nx >= image.width || ny < y0 || ny > y1 || !image.foreground(nx, ny)) continue;
            int& l = label[static_cast<std::size_t>(ny - y0) * image.width + nx];
            if (l < 0) l = id, stack.emplace_back(nx, ny);
          }
        }
      }
    std::sort(extents.begin(), extents.end());
    return extents;
  };
  EXPECT_EQ(components(a).size(), 1u) << "the uncut bar is one piece";
  EXPECT_EQ(components(b).size(), 1u) << "cut but not yet dragged, the pieces touch (the cut has no width)";
  const auto pieces = components(c);
  ASSERT_EQ(pieces.size(), 2u) << "the cube dragged off the bar should be a fragment of its own";
  const double tolerance = 1.0 / f.pixels_per_metre;
  // The bar did not move: its cut face is the cut, x = 10 mm; its far end x = 30 mm.
  EXPECT_NEAR(f.x(pieces[1].first), 0.010, tolerance);
  EXPECT_NEAR(f.x(pieces[1].second), 0.030, tolerance);
  // The cube moved with the stylus: x in [-5, 5] mm, 10 mm wide; the gap 5 mm.
  EXPECT_NEAR(f.x(pieces[0].first), -0.005, tolerance);
  EXPECT_NEAR(f.x(pieces[0].second), 0.005, tolerance);
  const double gap = (pieces[1].first - pieces[0].second - 1) / f.pixels_per_metre;
  EXPECT_NEAR(gap, 0.005, 2.0 * tolerance) << "the gap should be the stylus's 5 mm drag";
}

// kerf view RUN RUN: the same run side by side must give the same picture in both halves (one
// camera, one colour scale) up to rasterisation at the silhouette; a run re-stepped from its profile's samples (one that wrote no
// series of its own) must reproduce its recorded forces exactly (the models are deterministic).
TEST(ViewerScreenshot, SameRunSideBySideGivesIdenticalHalves) {
  const auto run = scratch("run_clay_pull");
  auto [code, out] = run_kerf("run clay_pull --model springs -o " + run.string());
  ASSERT_EQ(code, 0) << out;
  const auto shot = scratch("side_by_side.png");
  auto [code1, out1] = run_kerf("view " + run.string() + " " + run.string() +
                            " --no-text --camera front --width 1000 --height 600 --at 1.6 --screenshot " + shot.string());
  ASSERT_EQ(code1, 0) << out1;
  if (out1.find("re-stepped") != std::string::npos) {
    EXPECT_NE(out1.find("differs from the recorded profile by at most 0 N"), std::string::npos) << out1;
  }
  const PngImage image = PngImage::read(shot);
  const int half = image.width / 2;
  long foreground = 0, different = 0;
  // The body views fill the top 70% (the chart strip is below); compare the two halves there.
  for (int y = static_cast<int>(0.3 * image.height) + 1; y < image.height; ++y)
    for (int x = 0; x < half; ++x) {
      if (image.foreground(x, y)) ++foreground;
      const std::uint8_t* l = image.at(x, y);
      const std::uint8_t* r = image.at(x + half, y);
      if (l[0] != r[0] || l[1] != r[1] || l[2] != r[2]) ++different;
    }
  EXPECT_GT(foreground, 10000);
  // Identical up to edge pixels: Mesa's rasteriser snaps to the window's pixel grid, and the two
  // viewports sit at different window offsets, so a few silhouette pixels may fall differently.
  EXPECT_LT(different, foreground / 200) << different << " of " << foreground << " foreground pixels differ";
}
