// The fracture model (paper 001) on the scenes as a user runs them: gmsh meshes of the .geo
// files, trajectories from the scene files. Expected values are paper 001's closed forms with
// the sample dimensions of its §5.1: the steady cutting force J_c l (Eq. 10), l from the
// prism's cross-section; the cutting work J_c x cut area (Eqs. 3-5 with dU = 0).

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/resolve_scene.hpp"
#include "formats/scene/scene_reader.hpp"

#include <gtest/gtest.h>

using namespace kerf;

namespace {

struct SceneRun {
  Scene scene;
  TetMesh mesh;
  ForceProfile profile;
};

SceneRun run(const std::string& name, const std::function<void(Scene&)>& edit = {}) {
  SceneRun r{read_scene(resolve_scene(name)), {}, {}};
  if (edit) edit(r.scene);
  r.mesh = scene_mesh(r.scene);
  BuiltModel built = make_model("fracture", r.scene, r.mesh);
  r.profile = run_model(*built.model, {r.scene.tools.front().name}, sample_scene_trajectories(r.scene));
  return r;
}

std::vector<InteractionMode> modes(const ForceProfile& p, std::size_t from = 0) {
  std::vector<InteractionMode> seq;
  for (std::size_t k = from; k < p.rows.size(); ++k)
    if (seq.empty() || seq.back() != p.rows[k].mode) seq.push_back(p.rows[k].mode);
  return seq;
}

/// Work of the body's force along the path over the cutting samples, by the trapezoidal rule,
/// and the crack extents at the start and end of cutting.
struct CuttingWork {
  double work = 0.0, c_start = -1.0, c_end = 0.0, x_start = 0.0, x_end = 0.0;
};
CuttingWork cutting_work(const ForceProfile& p) {
  CuttingWork w;
  for (std::size_t k = 1; k < p.rows.size(); ++k) {
    if (p.rows[k].mode != InteractionMode::cutting) continue;
    w.work += 0.5 * (-p.rows[k].force - p.rows[k - 1].force).dot(p.rows[k].position - p.rows[k - 1].position);
    if (w.c_start < 0.0) {
      w.c_start = p.rows[k - 1].crack_extent;
      w.x_start = p.rows[k - 1].position.z();
    }
    w.c_end = p.rows[k].crack_extent;
    w.x_end = p.rows[k].position.z();
  }
  return w;
}

} // namespace

TEST(FractureOnScenes, PotatoRectCutSteadyForceIsJcTimesWidth) {
  const SceneRun r = run("potato_rect_cut");
  const double jc = r.scene.material.fracture_toughness;   // 200 J/m^2, paper 001 footnote 1
  const double width = r.scene.geometry.parameters.at("width"); // 20 mm, paper 001 §5.1
  int cutting = 0;
  for (const ProfileRow& row : r.profile.rows)
    if (row.mode == InteractionMode::cutting) {
      ++cutting;
      EXPECT_NEAR(row.force.z(), jc * width, 1e-6) << "t = " << row.t;
    }
  EXPECT_GT(cutting, 8000);
  EXPECT_NEAR(jc * width, 4.0, 1e-12);
}

TEST(FractureOnScenes, PotatoRectCutModeSequence) {
  using M = InteractionMode;
  const SceneRun r = run("potato_rect_cut");
  EXPECT_EQ(modes(r.profile),
            (std::vector<M>{M::no_contact, M::deformation_1, M::rupture, M::cutting, M::deformation_2, M::no_contact}));
}

TEST(FractureOnScenes, PotatoRectCutWorkIsToughnessTimesCutArea) {
  const SceneRun r = run("potato_rect_cut");
  const CuttingWork w = cutting_work(r.profile);
  const double area = r.scene.geometry.parameters.at("width") * (w.c_end - w.c_start);
  EXPECT_GT(area, 0.0);
  EXPECT_NEAR(w.work, r.scene.material.fracture_toughness * area, 1e-6 * r.scene.material.fracture_toughness * area);
}

TEST(FractureOnScenes, PotatoWedgeForceGrowsLinearlyWithDepth) {
  // Triangular section (paper 001 §5.1): at depth d below the apex the edge spans
  // l(d) = base_width d / depth, so the cutting force J_c l(d) grows linearly (Fig. 8c).
  const SceneRun r = run("potato_wedge_cut");
  const double jc = r.scene.material.fracture_toughness;
  const double b = r.scene.geometry.parameters.at("base_width"), h = r.scene.geometry.parameters.at("depth");
  int cutting = 0;
  for (const ProfileRow& row : r.profile.rows) {
    if (row.mode != InteractionMode::cutting) continue;
    const double d = h - row.position.z();
    EXPECT_NEAR(row.force.z(), jc * b * d / h, 1e-6) << "depth " << d;
    ++cutting;
  }
  EXPECT_GT(cutting, 5000);
}

TEST(FractureOnScenes, PotatoWedgeWorkIsToughnessTimesSweptTriangleArea) {
  // The area of the triangle's cross-section swept by the edge between depths d0 and d1 is
  // (b / 2h) (d1^2 - d0^2): the cutting work must be J_c times it.
  const SceneRun r = run("potato_wedge_cut");
  const double b = r.scene.geometry.parameters.at("base_width"), h = r.scene.geometry.parameters.at("depth");
  const CuttingWork w = cutting_work(r.profile);
  const double d0 = h - w.x_start, d1 = h - w.x_end;
  const double area = b / (2.0 * h) * (d1 * d1 - d0 * d0);
  EXPECT_NEAR(w.work, r.scene.material.fracture_toughness * area, 1e-6 * r.scene.material.fracture_toughness * area);
}

TEST(FractureOnScenes, ReenteringTheCutStartsInDeformation2) {
  using M = InteractionMode;
  const SceneRun r = run("potato_rect_cut", [](Scene& s) {
    auto& segments = s.tools.front().trajectory.segments;
    segments.push_back({TrajectorySegment::Kind::move, "re-enter", {0.020, 0.0, 0.003}, 0.001, 0.0});
  });
  // First cut and retreat as before; then, inside the crack, no contact until the edge reaches
  // the crack front, deformation in state 2, and cutting on.
  EXPECT_EQ(modes(r.profile), (std::vector<M>{M::no_contact, M::deformation_1, M::rupture, M::cutting,
                                               M::deformation_2, M::no_contact, M::deformation_2, M::cutting}));
}

TEST(FractureOnScenes, TwoLayerCutUsesEachLayersToughness) {
  const SceneRun r = run("two_layer_cut");
  ASSERT_EQ(r.scene.layers.size(), 2u);
  const double width = r.scene.geometry.parameters.at("width");
  const double interface = r.scene.geometry.parameters.at("depth") - r.scene.geometry.parameters.at("upper_thickness");
  double j_upper = 0.0, j_lower = 0.0;
  for (const Material& m : r.scene.layers) (m.region == "layer_upper" ? j_upper : j_lower) = m.fracture_toughness;
  int upper = 0, lower = 0;
  for (const ProfileRow& row : r.profile.rows) {
    if (row.mode != InteractionMode::cutting) continue;
    if (row.position.z() > interface + 1e-4) {
      EXPECT_NEAR(row.force.z(), j_upper * width, 1e-6);
      ++upper;
    } else if (row.position.z() < interface - 1e-4) {
      EXPECT_NEAR(row.force.z(), j_lower * width, 1e-6);
      ++lower;
    }
  }
  EXPECT_GT(upper, 1000);
  EXPECT_GT(lower, 1000);
}

TEST(FractureOnScenes, RefusesScenesItCannotRepresent) {
  // clay_tear declares tearing and has two sphere tools; clay_pull has a sphere, no blade.
  for (const char* name : {"clay_tear", "clay_pull"}) {
    const Scene s = read_scene(resolve_scene(name));
    EXPECT_THROW(require_model_for_scene("fracture", s), ModelMismatch) << name;
  }
  EXPECT_THROW(require_model_for_scene("no_such_model", read_scene(resolve_scene("potato_rect_cut"))), std::invalid_argument);
}
