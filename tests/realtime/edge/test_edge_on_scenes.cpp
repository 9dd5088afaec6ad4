// The edge model as `kerf run` builds and writes it on the scenes (gmsh meshes, the scenes'
// trajectories): the geometric cut driven by the blade's own passes, the cut mesh and its
// fragments in the run's directory and manifest; and clay_form (paper 000 §4), cut in two and a
// piece pulled. Expected values: the blocks' volumes in closed form (gmsh meshes the planar
// faces exactly). Kept beside the model's own tests (this program links kerf_experiments).

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "experiments/records/run_record.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

using namespace kerf;
namespace fs = std::filesystem;

namespace {

Scene scene(const std::string& name) {
  return read_scene(fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / (name + ".toml"));
}

/// Runs model edge on `s` and writes the run into a fresh temporary directory; returns the
/// manifest as written and the profile.
std::pair<nlohmann::json, ForceProfile> run_and_write(const Scene& s, const fs::path& dir) {
  fs::remove_all(dir);
  const TetMesh mesh = scene_mesh(s);
  BuiltModel built = make_model("edge", s, mesh);
  std::vector<std::string> names;
  for (const Tool& t : s.tools) names.push_back(t.name);
  const ForceProfile profile = run_model(*built.model, names, sample_scene_trajectories(s));
  write_run(dir, profile, run_manifest(s, built, mesh, profile, 0.0), &built);
  std::ifstream in(dir / "manifest.json");
  return {nlohmann::json::parse(in), profile};
}

} // namespace

TEST(EdgeOnScenes, PotatoCutStopsInsideAndLeavesOneSlitPiece) {
  // potato_rect_cut: the blade goes 10 mm into the 15 mm prism and retreats: one pass, a slit,
  // one fragment holding the whole 40 x 20 x 15 mm^3. The blade runs in the mesh's internal plane
  // x = 20 mm (the reference's crack path), so the slit opens along element faces: no
  // tetrahedron is divided, the nodes on the slit get their copies.
  const fs::path dir = fs::temp_directory_path() / "kerf_edge_potato";
  const auto [manifest, profile] = run_and_write(scene("potato_rect_cut"), dir);
  const nlohmann::json& cut = manifest.at("geometric_cut");
  EXPECT_EQ(cut.at("passes").get<int>(), 1);
  EXPECT_GT(cut.at("nodes").get<long>(), manifest.at("mesh").at("nodes").get<long>());
  EXPECT_EQ(cut.at("fragments").get<int>(), 1);
  EXPECT_FALSE(cut.contains("error"));
  const double volume = 0.040 * 0.020 * 0.015;
  EXPECT_NEAR(cut.at("fragment_volumes_m3")[0].get<double>(), volume, 1e-12 * volume);
  EXPECT_TRUE(fs::exists(dir / "cut_mesh.vtu"));
  fs::remove_all(dir);
}

TEST(EdgeOnScenes, ClayFormCutsInTwoAndPullsThePieceUnderTheStylus) {
  // clay_form with its stylus's pull shortened to 1 mm and no hold (the spring network is what
  // costs): the
  // blade goes through the 20 mm depth at x = 15 mm, giving 15 x 40 x 20 and 25 x 40 x 20 mm^3;
  // the stylus then pulls the 15 mm piece, which resists (force against the pull).
  Scene s = scene("clay_form");
  std::vector<TrajectorySegment>& stylus = s.tools[1].trajectory.segments;
  ASSERT_EQ(stylus.size(), 3u);
  stylus[1].target.z() = stylus[1].target.z() - 0.004; // pull 1 mm
  stylus.pop_back();                                   // no hold
  std::vector<TrajectorySegment>& blade = s.tools[0].trajectory.segments;
  ASSERT_EQ(blade.size(), 2u);
  blade[1].duration = 0.2;                             // the blade rests until the pull ends
  const fs::path dir = fs::temp_directory_path() / "kerf_edge_clay_form";
  const auto [manifest, profile] = run_and_write(s, dir);
  const nlohmann::json& cut = manifest.at("geometric_cut");
  EXPECT_FALSE(cut.contains("error"));
  ASSERT_EQ(cut.at("fragments").get<int>(), 2);
  std::vector<double> v = cut.at("fragment_volumes_m3").get<std::vector<double>>();
  std::sort(v.begin(), v.end());
  // The total to 1e-12 relative (conservation); each piece to within the snapping bound: nodes
  // within snap_tolerance x h of the plane are taken on it, which moves the cut by at most that
  // over the 40 x 20 mm cut face (h, the mean edge length there, below twice the 2.5 mm element
  // size).
  EXPECT_NEAR(v[0] + v[1], 0.040 * 0.040 * 0.020, 1e-12 * 0.040 * 0.040 * 0.020);
  const double snap_bound = 1e-4 * 5e-3 * 0.040 * 0.020;
  EXPECT_NEAR(v[0], 0.015 * 0.040 * 0.020, snap_bound);
  EXPECT_NEAR(v[1], 0.025 * 0.040 * 0.020, snap_bound);
  EXPECT_TRUE(cut.at("forming").contains("fragment"));
  EXPECT_TRUE(fs::exists(dir / "cut_mesh.vtu"));
  EXPECT_TRUE(fs::exists(dir / "formed_mesh.vtu"));
  // The stylus's last row: at the end of the pull, the body holds it back.
  const ProfileRow* last = nullptr;
  for (const ProfileRow& r : profile.rows)
    if (r.tool == "stylus") last = &r;
  ASSERT_NE(last, nullptr);
  EXPECT_TRUE(last->force.allFinite());
  EXPECT_LT(last->force.z(), 0.0);
  fs::remove_all(dir);
}
