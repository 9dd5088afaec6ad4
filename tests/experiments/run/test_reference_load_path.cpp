// The reference's load path follows the trajectory the models follow (reference_run.hpp,
// docs/reference.md "The load path"): potato_wedge_cut on a coarse mesh (4 mm, the default study's
// coarsest level), solved with 12 requested samples and with 107 (the 12 among them, so that every
// one of the 12 can be compared). Without the trajectory's vertices among the loads, the 12-sample
// run went from sample 6 (t = 12.045 s, blade going down at z = 5.955 mm) to sample 7 (t = 14.454
// s, coming back up at z = 5.954 mm) in one load: it never reached the cut's bottom at z = 5 mm,
// never held, never retreated, and reported at sample 7 the cutting force of the way down (2.50 N on
// the 4 mm mesh, where the dense run's blade, 0.95 mm up the retreat, feels a fraction of it).
// With the vertices (the cut's bottom at t = 13 s, the hold's end at t = 13.5 s) both runs pass
// through the same loads, and agree at every common output time — the retreat's included — within
// the study's target for the sampling uncertainty, 2 % of the peak force.

#include "experiments/reference_run/reference_run.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/study_plan.hpp"
#include "formats/trajectory/trajectory.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <iterator>

namespace kerf {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("kerf_reference_load_path_" + std::to_string(::getpid())) / name;
  fs::remove_all(dir);
  return dir;
}

TEST(ReferenceLoadPath, WedgeCutWith12And107SamplesAgreesAtEveryCommonTimeTheRetreatIncluded) {
  Scene scene = read_scene(fs::path(KERF_SCENES_DIR) / "potato_wedge_cut.toml");
  scene.geometry.element_size = 4e-3;
  const TetMesh mesh = scene_mesh(scene, MeshPurpose::reference);
  const std::size_t n = sample(scene.tools.front().trajectory).samples.size(); // 26.5 s at 1 kHz: 26 501
  ReferenceRunSettings coarse;
  coarse.fracture = ReferenceFracture::automatic;
  coarse.write_fields = false;
  coarse.sample_indices = reference_sample_indices(n, 12);
  ReferenceRunSettings dense = coarse;
  dense.sample_indices.clear();
  const std::vector<std::size_t> evenly = reference_sample_indices(n, 107);
  std::set_union(evenly.begin(), evenly.end(), coarse.sample_indices.begin(), coarse.sample_indices.end(),
                 std::back_inserter(dense.sample_indices));

  const fs::path coarse_dir = scratch("n12");
  const ReferenceResult a = run_reference(scene, mesh, coarse, coarse_dir);
  const ReferenceResult b = run_reference(scene, mesh, dense, scratch("n107"));
  ASSERT_TRUE(a.complete()) << a.stopped;
  ASSERT_TRUE(b.complete()) << b.stopped;

  // The cut's bottom and the hold's end are loads of the 12-sample run (vertices of the motion),
  // and the manifest says so.
  std::ifstream in(coarse_dir / "manifest.json");
  const nlohmann::json m = nlohmann::json::parse(in);
  std::vector<std::size_t> vertices;
  for (const auto& record : m.at("samples"))
    if (record.at("load") == "vertex") vertices.push_back(record.at("index").get<std::size_t>());
  EXPECT_EQ(vertices, (std::vector<std::size_t>{13000, 13500}));
  EXPECT_EQ(m.at("solver").at("load_path").at("requested_samples").get<std::size_t>(), 12u);

  double peak = 0.0;
  for (const ProfileRow& r : b.profile.rows) peak = std::max(peak, r.force.norm());
  ASSERT_GT(peak, 0.0);
  std::size_t compared = 0, retreat = 0;
  for (const ProfileRow& r : a.profile.rows) {
    const auto same = std::find_if(b.profile.rows.begin(), b.profile.rows.end(), [&](const ProfileRow& d) { return std::abs(d.t - r.t) < 1e-9; });
    ASSERT_NE(same, b.profile.rows.end()) << "t = " << r.t;
    EXPECT_LE((r.force - same->force).norm(), 0.02 * peak) << "t = " << r.t << " s: " << r.force.norm() << " N against " << same->force.norm() << " N";
    ++compared;
    retreat += r.t > 13.5;
  }
  EXPECT_EQ(compared, a.profile.rows.size());
  EXPECT_GE(retreat, 5u); // samples 7 to 11 of the 12 lie on the retreat
}

} // namespace
} // namespace kerf
