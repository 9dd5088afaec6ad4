// The spring model as `kerf run` builds and writes it on a scene (gmsh mesh, the scene's
// trajectory): the embedded fine mesh written as a .vtu series with a .pvd, whose last frame is
// the fine mesh moved by the final network state. The expected positions are computed here
// independently: a fresh trilinear NetworkEmbedding of the frame's rest points (its points minus
// its `displacement`) in the model's final network. Links kerf_experiments (scenes, runs) and
// VTK (to read the files back).

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "experiments/records/run_record.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "realtime/springs/network_embedding.hpp"
#include "realtime/springs/spring_network_model.hpp"

#include <gtest/gtest.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

using namespace kerf;
namespace fs = std::filesystem;

TEST(SpringsOnScenes, ClayPullWritesTheEmbeddedMeshSeries) {
  const Scene scene = read_scene(fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / "clay_pull.toml");
  const TetMesh mesh = scene_mesh(scene);
  BuiltModel built = make_model("springs", scene, mesh, {{"integrator", "implicit"}});
  // The model proper behind the recording wrapper (BuiltModel::core_model).
  const auto* springs = dynamic_cast<const SpringNetworkModel*>(&built.core_model());
  ASSERT_NE(springs, nullptr);
  std::vector<std::string> names;
  for (const Tool& t : scene.tools) names.push_back(t.name);
  const std::vector<SampledTrajectory> trajectories = sample_scene_trajectories(scene);
  const ForceProfile profile = run_model(*built.model, names, trajectories);
  const fs::path dir = fs::temp_directory_path() / "kerf_test_springs_series";
  fs::remove_all(dir);
  write_run(dir, profile, run_manifest(scene, built, mesh, profile, 0.0), &built);

  std::ifstream manifest_file(dir / "manifest.json");
  const nlohmann::json manifest = nlohmann::json::parse(manifest_file);
  ASSERT_TRUE(manifest.contains("fields"));
  EXPECT_EQ(manifest["fields"]["series"], "springs.pvd");
  const int frames = manifest["fields"]["frames"].get<int>();
  EXPECT_GE(frames, 100); // one per 1/100 of the trajectory, and the final state

  // The .pvd lists every frame in time order; the last is at the last sample's time.
  std::ifstream pvd(dir / "springs.pvd");
  std::stringstream text;
  text << pvd.rdbuf();
  const std::string body = text.str();
  // Each <DataSet timestep="T" ... file="F"/> element, in file order.
  const auto attribute = [&body](std::size_t from, std::size_t to, const std::string& name) {
    const std::size_t at = body.find(name + "=\"", from);
    if (at == std::string::npos || at >= to) return std::string();
    const std::size_t begin = at + name.size() + 2;
    return body.substr(begin, body.find('"', begin) - begin);
  };
  std::vector<std::pair<double, std::string>> listed;
  for (std::size_t at = body.find("<DataSet"); at != std::string::npos; at = body.find("<DataSet", at + 1)) {
    const std::size_t end = body.find('>', at);
    const std::string timestep = attribute(at, end, "timestep"), file = attribute(at, end, "file");
    ASSERT_FALSE(timestep.empty() || file.empty()) << body.substr(at, end - at);
    listed.emplace_back(std::stod(timestep), file);
  }
  ASSERT_EQ(static_cast<int>(listed.size()), frames);
  for (std::size_t k = 1; k < listed.size(); ++k) EXPECT_GT(listed[k].first, listed[k - 1].first);
  const double dt = 1.0 / trajectories.front().rate;
  EXPECT_NEAR(listed.back().first, static_cast<double>(trajectories.front().samples.size()) * dt, 1e-9);

  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName((dir / listed.back().second).string().c_str());
  reader->Update();
  vtkUnstructuredGrid* grid = reader->GetOutput();
  ASSERT_NE(grid, nullptr);
  ASSERT_EQ(grid->GetNumberOfCells(), mesh.tets.rows()); // untorn: the scene's tetrahedra
  ASSERT_EQ(grid->GetNumberOfPoints(), mesh.nodes.rows());
  vtkDataArray* displacement = grid->GetPointData()->GetArray("displacement");
  ASSERT_NE(displacement, nullptr);
  const auto n = static_cast<Eigen::Index>(grid->GetNumberOfPoints());
  Eigen::MatrixXd written(n, 3), rest(n, 3);
  for (Eigen::Index p = 0; p < n; ++p)
    for (int i = 0; i < 3; ++i) {
      written(p, i) = grid->GetPoint(p)[i];
      rest(p, i) = written(p, i) - displacement->GetComponent(p, i);
    }
  // The expected positions: the scene mesh's nodes embedded afresh in the final network, each
  // matched to the written point with the same rest position (to 1 nm).
  const NetworkEmbedding embedding(springs->network(), mesh.nodes, EmbeddingScheme::trilinear);
  Eigen::MatrixXd expected(mesh.nodes.rows(), 3);
  embedding.apply(springs->network(), springs->positions(), expected);
  const auto key = [](const Eigen::RowVector3d& r) {
    return std::array<long long, 3>{std::llround(r.x() * 1e9), std::llround(r.y() * 1e9), std::llround(r.z() * 1e9)};
  };
  std::map<std::array<long long, 3>, Eigen::Index> node_at;
  for (Eigen::Index p = 0; p < mesh.nodes.rows(); ++p) node_at[key(mesh.nodes.row(p))] = p;
  double worst = 0.0;
  for (Eigen::Index p = 0; p < n; ++p) {
    const auto it = node_at.find(key(rest.row(p)));
    ASSERT_NE(it, node_at.end()) << "written point " << p << " has no scene node at its rest position";
    const double d = (written.row(p) - expected.row(it->second)).cwiseAbs().maxCoeff();
    worst = std::max(worst, d);
  }
  EXPECT_LT(worst, 1e-12);
  // The pull moved the fine mesh: by about the 6 mm pull at the stylus.
  EXPECT_GT((written - rest).rowwise().norm().maxCoeff(), 4e-3);
  EXPECT_GT(embedding.embedded_count(), 0);
}

TEST(SpringsOnScenes, ClayPullWithAGraspStiffnessGraspsCompliantly) {
  // The builder passes the scene's grasp_stiffness k and grasp_radius a to the network: the
  // manifest says "compliant", no node is attached rigidly, and the anchors' stiffnesses sum to
  // the layer's ∫ k (1 − r²/a²) dA = k π a²/2 (the independent value). Without the key the rigid
  // grasp is unchanged.
  // clay_pull.toml sets k = 1.9e9 N/m^3 (its stylus's grasp_stiffness).
  Scene scene = read_scene(fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / "clay_pull.toml");
  const TetMesh mesh = scene_mesh(scene);
  ASSERT_TRUE(scene.tools.front().grasp_radius && scene.tools.front().grasp_stiffness);
  const double k = 1.9e9, a = *scene.tools.front().grasp_radius;
  EXPECT_EQ(*scene.tools.front().grasp_stiffness, k);
  {
    Scene rigid_scene = scene;
    rigid_scene.tools.front().grasp_stiffness.reset();
    const BuiltModel rigid = make_model("springs", rigid_scene, mesh, {});
    EXPECT_FALSE(rigid.parameters.contains("grasp"));
    EXPECT_GT(rigid.parameters["attached_nodes"][0].get<int>(), 0);
  }
  const BuiltModel built = make_model("springs", scene, mesh, {});
  const nlohmann::json& p = built.parameters;
  ASSERT_TRUE(p.contains("grasp"));
  EXPECT_EQ(p["grasp"].get<std::string>().rfind("compliant", 0), 0u);
  EXPECT_EQ(p["grasp_stiffness_N_per_m3"].get<double>(), k);
  EXPECT_EQ(p["grasp_disc_radius_m"].get<double>(), a);
  EXPECT_EQ(p["attached_nodes"][0].get<int>(), 0);
  EXPECT_NEAR(p["grasp_anchors"][0]["stiffness_sum_N_per_m"].get<double>(), k * M_PI * a * a / 2.0, 1e-8 * k * M_PI * a * a / 2.0);
}

TEST(SpringsOnScenes, ACrushedNetworkHoldsStillInsteadOfFlyingOffAsTheBladeWithdraws) {
  // potato_rect_cut's blade pressed 10 mm into a 4³ network (h = 10 mm: the cells under the edge
  // crushed flat), held and drawn back: on the way back some implicit steps accept no step of
  // their kept-factor iteration (a factor far from the crushed tangent). Such a step holds the
  // network (x = xₙ, v = 0) rather than returning the predictor xₙ + h vₙ, which would carry
  // the last velocity on unopposed, sample after sample (the force on the blade then grew without
  // bound, to 10²⁰ N). Expected: no force on the blade after the press beyond the press's own
  // largest (the network only relaxes as the blade leaves), and failed steps that say so.
  Scene scene = read_scene(fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / "potato_rect_cut.toml");
  if (!scene.springs) scene.springs = SpringsModelSettings{};
  scene.springs->cells = 4;
  const TetMesh mesh = scene_mesh(scene);
  BuiltModel built = make_model("springs", scene, mesh, {});
  const auto* springs = dynamic_cast<const SpringNetworkModel*>(&built.core_model());
  ASSERT_NE(springs, nullptr);
  std::vector<std::string> names;
  for (const Tool& t : scene.tools) names.push_back(t.name);
  const ForceProfile profile = run_model(*built.model, names, sample_scene_trajectories(scene));
  // The deepest sample ends the press; the hold and the withdrawal follow.
  std::size_t deepest = 0;
  for (std::size_t i = 0; i < profile.rows.size(); ++i)
    if (profile.rows[i].position.z() < profile.rows[deepest].position.z()) deepest = i;
  double press = 0.0, after = 0.0;
  for (std::size_t i = 0; i < profile.rows.size(); ++i) (i <= deepest ? press : after) = std::max(i <= deepest ? press : after, profile.rows[i].force.norm());
  EXPECT_GT(press, 1.0);
  EXPECT_LE(after, press) << "largest force after the press " << after << " N, during it " << press << " N";
  EXPECT_GT(springs->unconverged_samples(), 0); // the withdrawal does fail steps (and says so)
}
