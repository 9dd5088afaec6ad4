// Tests for formats/scene/scene_reader.cpp: every scene of experiments/scenes reads and carries
// the papers' numbers; every malformed scene of bad_scenes/ is rejected with file:line:column, the
// key and what was expected (bad_scenes/expected.txt); the reader's conversions and file lookup.

#include "formats/scene/scene_reader.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace kerf {
namespace {

namespace fs = std::filesystem;

const fs::path scenes_dir = fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes";
const fs::path bad_dir = fs::path(KERF_TEST_DATA_DIR) / "bad_scenes";

Scene scene(const std::string& name) { return read_scene(scenes_dir / (name + ".toml")); }

/// Relative tolerance for values written with units ("15 mm" is 15 * 1e-3 in floating point).
void expect_si(double actual, double expected) { EXPECT_NEAR(actual, expected, 1e-12 * std::abs(expected)); }

void expect_vec(const Eigen::Vector3d& actual, double x, double y, double z) {
  EXPECT_NEAR(actual.x(), x, 1e-15);
  EXPECT_NEAR(actual.y(), y, 1e-15);
  EXPECT_NEAR(actual.z(), z, 1e-15);
}

const Tool& only_tool(const Scene& s) {
  EXPECT_EQ(s.tools.size(), 1u);
  return s.tools.front();
}

// --- every scene ---------------------------------------------------------------------------------

TEST(Scenes, EverySceneFileReads) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(scenes_dir))
    if (entry.path().extension() == ".toml") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  ASSERT_GE(files.size(), 8u) << "the scenes of paper 000, 001 and 002 are in " << scenes_dir;
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.string());
    Scene s;
    ASSERT_NO_THROW(s = read_scene(f));
    EXPECT_EQ(s.name, f.stem().string()); // a scene is named after its file
    EXPECT_FALSE(s.description.empty());
    EXPECT_TRUE(s.geometry.source.is_absolute());
    EXPECT_TRUE(fs::exists(s.geometry.source));
    EXPECT_GT(s.geometry.element_size, 0.0);
    EXPECT_EQ(s.material.region, "body");
    EXPECT_FALSE(s.supports.empty());
    ASSERT_GE(s.tools.size(), 1u);
    for (const Tool& t : s.tools) {
      EXPECT_DOUBLE_EQ(t.trajectory.rate, 1000.0);
      EXPECT_FALSE(t.trajectory.segments.empty());
    }
    // every cutting scene carries paper 001's responses (the fracture model and its calibration need them)
    if (s.phenomena.contains(Phenomenon::cutting)) {
      EXPECT_TRUE(s.fracture.has_value());
    }
    EXPECT_EQ(s.phenomena.contains(Phenomenon::layers), !s.layers.empty());
  }
}

// --- paper 001 §5.1 ---------------------------------------------------------------------------

TEST(Scenes, PotatoRectCutHasPaper001Values) {
  const Scene s = scene("potato_rect_cut");
  EXPECT_EQ(s.phenomena, (PhenomenonSet{Phenomenon::deformation, Phenomenon::cutting, Phenomenon::friction}));
  EXPECT_EQ(s.geometry.kind, SceneGeometry::Kind::geo);
  EXPECT_EQ(s.geometry.source.filename(), "rect_prism.geo");
  // paper 001 §5.1: "15 mm deep, 20 mm wide, and 40 mm long"
  expect_si(s.geometry.parameters.at("depth"), 0.015);
  expect_si(s.geometry.parameters.at("width"), 0.020);
  expect_si(s.geometry.parameters.at("length"), 0.040);
  EXPECT_EQ(s.geometry.parameters.at("cut_normal"), 0.0);
  expect_si(s.geometry.parameters.at("cut_offset"), 0.020);
  // paper 001 footnote 1: potato 0.2 kJ/m^2
  EXPECT_DOUBLE_EQ(s.material.fracture_toughness, 200.0);
  EXPECT_EQ(s.material.law, MaterialLaw::neo_hookean);
  EXPECT_DOUBLE_EQ(s.material.youngs_modulus, 3e6);
  EXPECT_DOUBLE_EQ(s.material.poisson_ratio, 0.45);
  // paper 001 §5.1: bonded to a plate
  ASSERT_EQ(s.supports.size(), 1u);
  EXPECT_EQ(s.supports[0].surface, "support");
  EXPECT_EQ(s.supports[0].kind, Support::Kind::bonded);

  const Tool& blade = only_tool(s);
  EXPECT_EQ(blade.kind, Tool::Kind::blade);
  expect_vec(blade.blade.edge_direction, 0, 1, 0);
  expect_vec(blade.blade.cutting_direction, 0, 0, -1);
  expect_si(blade.blade.edge_length, 0.030);
  expect_si(blade.blade.wedge_angle, 15.0 * std::numbers::pi / 180.0);
  // Not the paper's razor (~0.1 mm): the thinnest blade the reference's cohesive law can cut at
  // the scene's σ_c = 1 MPa (δ_f = 2 J_c/σ_c = 0.4 mm; the scene's comment, docs/cohesive-fracture.md).
  expect_si(blade.blade.thickness, 5e-4);
  expect_si(s.material.cohesive_strength, 1e6);

  // approach 1 mm, cut 10 mm at 1 mm/s (paper 001 §5.1), dwell 0.5 s, retreat
  const TrajectorySpec& tr = blade.trajectory;
  expect_vec(tr.start, 0.020, 0.0, 0.016);
  ASSERT_EQ(tr.segments.size(), 4u);
  EXPECT_EQ(tr.segments[0].label, "approach");
  expect_vec(tr.segments[0].target, 0.020, 0.0, 0.015);
  EXPECT_EQ(tr.segments[1].label, "cut");
  EXPECT_EQ(tr.segments[1].kind, TrajectorySegment::Kind::move);
  expect_vec(tr.segments[1].target, 0.020, 0.0, 0.005);
  expect_si(tr.segments[1].speed, 1e-3);
  EXPECT_EQ(tr.segments[2].kind, TrajectorySegment::Kind::dwell);
  EXPECT_DOUBLE_EQ(tr.segments[2].duration, 0.5);
  EXPECT_EQ(tr.segments[3].label, "retreat");
  expect_vec(tr.segments[3].target, 0.020, 0.0, 0.016);
  for (const TrajectorySegment& seg : tr.segments)
    if (seg.kind == TrajectorySegment::Kind::move) expect_si(seg.speed, 1e-3);

  ASSERT_TRUE(s.fracture.has_value());
  EXPECT_GT(s.fracture->rupture_force_per_length, s.material.fracture_toughness); // rupture peak above the plateau
  EXPECT_LT(s.fracture->crack_deflection, s.fracture->rupture_deflection);
  EXPECT_FALSE(s.voxel.has_value());
}

TEST(Scenes, PotatoWedgeCutHasPaper001Values) {
  const Scene s = scene("potato_wedge_cut");
  EXPECT_EQ(s.geometry.source.filename(), "tri_prism.geo");
  // paper 001 §5.1: "17 mm deep, 18 mm wide at the base, and 50 mm long"
  expect_si(s.geometry.parameters.at("depth"), 0.017);
  expect_si(s.geometry.parameters.at("base_width"), 0.018);
  expect_si(s.geometry.parameters.at("length"), 0.050);
  EXPECT_DOUBLE_EQ(s.material.fracture_toughness, 200.0); // paper 001 footnote 1
  const TrajectorySpec& tr = only_tool(s).trajectory;
  expect_vec(tr.start, 0.025, 0.0, 0.018);                // 1 mm above the apex
  ASSERT_EQ(tr.segments.size(), 4u);
  expect_vec(tr.segments[1].target, 0.025, 0.0, 0.005);   // 12 mm below the apex
  expect_si(tr.segments[1].speed, 1e-3);                  // paper 001 §5.1
}

TEST(Scenes, LiverPrismCutHasPaper001Values) {
  const Scene s = scene("liver_prism_cut");
  // paper 001 §5.1: "10 mm deep, 20 mm wide, and 90 mm long"
  expect_si(s.geometry.parameters.at("depth"), 0.010);
  expect_si(s.geometry.parameters.at("width"), 0.020);
  expect_si(s.geometry.parameters.at("length"), 0.090);
  expect_si(s.geometry.parameters.at("cut_offset"), 0.045);
  const TrajectorySpec& tr = only_tool(s).trajectory;
  expect_vec(tr.start, 0.045, 0.0, 0.011);
  ASSERT_EQ(tr.segments.size(), 3u);
  expect_vec(tr.segments[1].target, 0.045, 0.0, 0.003);   // 7 mm deep
  expect_vec(tr.segments[2].target, 0.045, 0.0, 0.011);   // retreat
  for (const TrajectorySegment& seg : tr.segments) expect_si(seg.speed, 1e-3);
}

// --- paper 001 §6: two layers ---------------------------------------------------------------------

TEST(Scenes, TwoLayerCutHasAFullMaterialPerLayer) {
  const Scene s = scene("two_layer_cut");
  EXPECT_TRUE(s.phenomena.contains(Phenomenon::layers));
  EXPECT_EQ(s.geometry.source.filename(), "layered_block.geo");
  expect_si(s.geometry.parameters.at("upper_thickness"), 0.006);
  ASSERT_EQ(s.layers.size(), 2u);
  EXPECT_EQ(s.layers[0].region, "layer_upper");
  EXPECT_EQ(s.layers[1].region, "layer_lower");
  // paper 001 §6: the layers differ in toughness; the rest is the base material
  EXPECT_GT(s.layers[0].fracture_toughness, s.layers[1].fracture_toughness);
  EXPECT_DOUBLE_EQ(s.layers[1].fracture_toughness, 200.0);
  for (const Material& m : s.layers) {
    EXPECT_EQ(m.law, s.material.law);
    EXPECT_EQ(m.youngs_modulus, s.material.youngs_modulus);
    EXPECT_EQ(m.poisson_ratio, s.material.poisson_ratio);
    EXPECT_EQ(m.density, s.material.density);
    EXPECT_EQ(m.friction_coefficient, s.material.friction_coefficient);
  }
  // 14 mm deep through the 20 mm block
  const TrajectorySpec& tr = only_tool(s).trajectory;
  expect_vec(tr.segments[0].target, 0.020, 0.0, 0.020);
  expect_vec(tr.segments[1].target, 0.020, 0.0, 0.006);
}

// --- paper 002 §3.2, Table 1 ----------------------------------------------------------------------

void expect_table_1(const Scene& s) {
  ASSERT_TRUE(s.voxel.has_value());
  // paper 002 Table 1 (sponge), as printed
  EXPECT_DOUBLE_EQ(s.voxel->elastic_coefficient, 20.0);       // N/m^2
  EXPECT_DOUBLE_EQ(s.voxel->friction_coefficient, 0.8);
  EXPECT_DOUBLE_EQ(s.voxel->damping_coefficient, 0.5);        // N s/m^2
  EXPECT_DOUBLE_EQ(s.voxel->critical_force_cutting, 0.1);     // N
  EXPECT_DOUBLE_EQ(s.voxel->critical_force_depth, 0.3);       // N
  expect_si(s.voxel->advance_length, 0.02e-3);                // 0.02 mm
  EXPECT_EQ(s.voxel->grid, (std::array<int, 3>{10, 20, 20})); // paper 002 §4
  EXPECT_DOUBLE_EQ(s.material.friction_coefficient, 0.8);     // Table 1
  EXPECT_DOUBLE_EQ(s.material.damping, 0.5);                  // Table 1
  // paper 002 §3.2: a cube of 1 mm edge; the stick tip is 0.04 mm across
  for (const char* p : {"length", "width", "depth"}) expect_si(s.geometry.parameters.at(p), 1e-3);
  EXPECT_EQ(s.geometry.parameters.at("cut_normal"), 1.0);
  EXPECT_EQ(s.geometry.parameters.at("cut_offset"), 0.0);
  const Tool& stick = only_tool(s);
  EXPECT_EQ(stick.kind, Tool::Kind::sphere);
  expect_si(stick.radius, 0.02e-3);
  EXPECT_TRUE(s.phenomena.contains(Phenomenon::cutting));
}

TEST(Scenes, SpongeProportionalHasTable1AndAProportionalDepthCut) {
  const Scene s = scene("sponge_cut_proportional");
  expect_table_1(s);
  const TrajectorySpec& tr = only_tool(s).trajectory;
  ASSERT_EQ(tr.segments.size(), 3u);
  // the cut moves down and along together: from x = 0.1 mm at the surface to x = 0.9 mm, 0.5 mm deep
  const Eigen::Vector3d from = tr.segments[0].target, to = tr.segments[1].target;
  expect_vec(from, 0.1e-3, 0.0, 1.02e-3);
  expect_vec(to, 0.9e-3, 0.0, 0.52e-3);
  EXPECT_EQ(tr.segments[1].label, "cut");
  EXPECT_GT(to.x(), from.x()); // along x ...
  EXPECT_LT(to.z(), from.z()); // ... and down at once
}

TEST(Scenes, SpongeConstantHasTable1AndAConstantDepthCut) {
  const Scene s = scene("sponge_cut_constant");
  expect_table_1(s);
  const TrajectorySpec& tr = only_tool(s).trajectory;
  ASSERT_EQ(tr.segments.size(), 4u);
  expect_vec(tr.segments[1].target, 0.1e-3, 0.0, 0.52e-3); // straight down to 0.5 mm tip depth
  expect_vec(tr.segments[2].target, 0.9e-3, 0.0, 0.52e-3); // then along x at that depth
  EXPECT_EQ(tr.segments[2].label, "cut");
}

// --- paper 000 §2.1, §2.2 --------------------------------------------------------------------------

TEST(Scenes, ClayPullIsDeformationOnly) {
  const Scene s = scene("clay_pull");
  EXPECT_EQ(s.phenomena, PhenomenonSet{Phenomenon::deformation});
  EXPECT_FALSE(s.fracture.has_value());
  const Tool& stylus = only_tool(s);
  EXPECT_EQ(stylus.kind, Tool::Kind::sphere);
  // touching the centre of the 40 x 40 x 20 mm block's top, pulled straight up 6 mm, grasping a
  // 4 mm disc through a compliant layer
  expect_vec(stylus.trajectory.start, 0.020, 0.0, 0.020 + stylus.radius);
  expect_vec(stylus.trajectory.segments[0].target, 0.020, 0.0, 0.028);
  ASSERT_TRUE(stylus.grasp_radius && stylus.grasp_stiffness);
  EXPECT_DOUBLE_EQ(*stylus.grasp_radius, 0.004);
  EXPECT_DOUBLE_EQ(*stylus.grasp_stiffness, 1.9e9);
  EXPECT_EQ(stylus.trajectory.segments.back().kind, TrajectorySegment::Kind::dwell);
}

TEST(Scenes, ClayTearPullsTwoStylusesApart) {
  const Scene s = scene("clay_tear");
  EXPECT_TRUE(s.phenomena.contains(Phenomenon::tearing));
  ASSERT_EQ(s.tools.size(), 2u);
  ASSERT_EQ(s.supports.size(), 1u);
  EXPECT_EQ(s.supports[0].kind, Support::Kind::sliding);
  expect_si(s.geometry.parameters.at("cut_offset"), 0.030);
  // 10 mm each, along -x and +x
  const TrajectorySpec& left = s.tools[0].trajectory;
  const TrajectorySpec& right = s.tools[1].trajectory;
  EXPECT_NEAR(left.segments[0].target.x() - left.start.x(), -0.010, 1e-15);
  EXPECT_NEAR(right.segments[0].target.x() - right.start.x(), 0.010, 1e-15);
  EXPECT_NEAR(left.start.x(), 0.015, 1e-15);
  EXPECT_NEAR(right.start.x(), 0.045, 1e-15);
}

// --- malformed scenes ---------------------------------------------------------------------------

struct Expectation {
  std::string file, position, key, fragment;
};

std::vector<Expectation> read_expectations() {
  std::vector<Expectation> out;
  std::ifstream in(bad_dir / "expected.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    const auto bar = line.find(" | ");
    std::istringstream head(line.substr(0, bar));
    Expectation e;
    head >> e.file >> e.position;
    std::getline(head >> std::ws, e.key); // the rest: a key path, or "TOML syntax" for parse errors
    while (!e.key.empty() && e.key.back() == ' ') e.key.pop_back();
    e.fragment = bar == std::string::npos ? "" : line.substr(bar + 3);
    out.push_back(e);
  }
  return out;
}

TEST(BadScenes, EachIsRejectedAtTheRightPlaceWithTheKey) {
  const auto expectations = read_expectations();
  ASSERT_GE(expectations.size(), 12u);
  for (const Expectation& e : expectations) {
    SCOPED_TRACE(e.file);
    const fs::path file = bad_dir / e.file;
    ASSERT_TRUE(fs::exists(file));
    std::string message;
    try {
      (void)read_scene(file);
    } catch (const SceneError& err) {
      message = err.what();
    }
    ASSERT_FALSE(message.empty()) << "no SceneError";
    // "FILE:LINE:COLUMN: KEY: MESSAGE"
    const std::string prefix = file.string() + ":" + e.position + ": " + e.key + ": ";
    EXPECT_EQ(message.rfind(prefix, 0), 0u) << message << "\n  expected prefix: " << prefix;
    EXPECT_NE(message.find(e.fragment), std::string::npos) << message;
  }
}

TEST(BadScenes, EveryFileIsListed) {
  std::set<std::string> listed;
  for (const Expectation& e : read_expectations()) listed.insert(e.file);
  for (const auto& entry : fs::directory_iterator(bad_dir))
    if (entry.path().extension() == ".toml") {
      EXPECT_TRUE(listed.count(entry.path().filename().string())) << entry.path() << " is not in expected.txt";
    }
}

// --- reader details, on scenes written to a temporary folder ----------------------------------------

class SceneReaderTest : public ::testing::Test {
protected:
  void SetUp() override {
    m_dir = fs::temp_directory_path() /
            ("kerf_scene_test_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(m_dir);
    fs::create_directories(m_dir);
  }
  void TearDown() override { fs::remove_all(m_dir); }

  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = m_dir / name;
    std::ofstream(p) << text;
    return p;
  }

  /// A minimal valid scene; `tool` and `extra` are spliced in.
  static std::string minimal(const std::string& geometry = "geo = \"rect_prism.geo\"\nelement_size = 0.002\n",
                             const std::string& tool_shape = blade_shape) {
    return "[scene]\nname = \"t\"\nphenomena = [\"deformation\", \"cutting\"]\n"
           "[geometry]\n" + geometry +
           "[material]\nlaw = \"st-venant-kirchhoff\"\nyoungs_modulus = 3e6\npoisson_ratio = 0.3\n"
           "density = 1000\nfracture_toughness = \"0.2 kJ/m^2\"\ncohesive_strength = \"0.5 N/mm^2\"\n"
           "[[supports]]\nsurface = \"support\"\nkind = \"sliding\"\n"
           "[[tools]]\nname = \"b\"\n" + tool_shape +
           "[tools.trajectory]\nrate = 2000\nstart = [0.02, 0, \"16 mm\"]\n"
           "[[tools.trajectory.segments]]\nkind = \"move\"\nto = [0.02, 0, 0.005]\nspeed = 0.001\n";
  }
  static constexpr const char* blade_shape =
      "kind = \"blade\"\nedge_direction = [0, 2, 0]\ncutting_direction = [0, 0, -0.5]\n"
      "edge_length = 0.03\nwedge_angle = 0.26\nthickness = \"100 um\"\n";

  fs::path m_dir;
};

// The three laws by their scene names, and the name each is written back as (the reference cache
// key's material line).
TEST_F(SceneReaderTest, MaterialLawsReadByName) {
  for (const MaterialLaw law : {MaterialLaw::neo_hookean, MaterialLaw::decoupled_neo_hookean, MaterialLaw::st_venant_kirchhoff}) {
    std::string text = minimal();
    const std::string from = "law = \"st-venant-kirchhoff\"";
    text.replace(text.find(from), from.size(), std::string("law = \"") + material_law_name(law) + "\"");
    EXPECT_EQ(read_scene(write("s.toml", text)).material.law, law) << material_law_name(law);
  }
}

TEST_F(SceneReaderTest, SINumbersAndUnitsMixAndDirectionsAreNormalised) {
  const Scene s = read_scene(write("s.toml", minimal()));
  EXPECT_EQ(s.material.law, MaterialLaw::st_venant_kirchhoff);
  EXPECT_DOUBLE_EQ(s.material.fracture_toughness, 200.0);
  EXPECT_DOUBLE_EQ(s.material.cohesive_strength, 0.5e6);
  EXPECT_EQ(s.material.friction_coefficient, 0.0); // not required without "friction"
  EXPECT_EQ(s.material.damping, 0.0);              // optional
  EXPECT_EQ(s.supports[0].kind, Support::Kind::sliding);
  const Tool& t = s.tools[0];
  expect_vec(t.blade.edge_direction, 0, 1, 0);
  expect_vec(t.blade.cutting_direction, 0, 0, -1);
  EXPECT_DOUBLE_EQ(t.blade.wedge_angle, 0.26);
  expect_si(t.blade.thickness, 1e-4);
  EXPECT_DOUBLE_EQ(t.trajectory.rate, 2000.0);
  expect_vec(t.trajectory.start, 0.02, 0.0, 0.016);
  EXPECT_EQ(t.trajectory.segments[0].label, "");
  EXPECT_EQ(s.file, m_dir / "s.toml");
}

TEST_F(SceneReaderTest, GeometryIsFoundBesideTheSceneFirst) {
  write("rect_prism.geo", "// local copy\nlength = 1;\nPhysical Surface(\"support\") = {1};\n");
  const Scene s = read_scene(write("s.toml", minimal()));
  EXPECT_EQ(s.geometry.source, m_dir / "rect_prism.geo");
}

TEST_F(SceneReaderTest, TheElementDegreeIsTheScenesOrLinear) {
  EXPECT_EQ(read_scene(write("s.toml", minimal())).geometry.element_degree, 1);
  EXPECT_EQ(read_scene(write("s.toml", minimal("geo = \"rect_prism.geo\"\nelement_size = 0.002\nelement_degree = 2\n")))
                .geometry.element_degree,
            2);
}

TEST_F(SceneReaderTest, GeometryIsFoundOnKerfGeoPath) {
  const fs::path other = m_dir / "other";
  fs::create_directories(other);
  std::ofstream(other / "mine.stl") << "solid x\nendsolid x\n";
  ASSERT_EQ(setenv("KERF_GEO_PATH", ("/nonexistent:" + other.string()).c_str(), 1), 0);
  const auto search = geometry_search_path();
  EXPECT_EQ(search.back(), other);
  const Scene s = read_scene(write("s.toml", minimal("stl = \"mine.stl\"\nstl_scale = 0.001\nelement_size = \"1 mm\"\n")));
  unsetenv("KERF_GEO_PATH");
  EXPECT_EQ(s.geometry.kind, SceneGeometry::Kind::stl);
  EXPECT_EQ(s.geometry.source, other / "mine.stl");
  EXPECT_DOUBLE_EQ(s.geometry.stl_scale, 0.001);
}

TEST_F(SceneReaderTest, RecordedTrajectoryIsResolvedBesideTheScene) {
  write("session.csv", "t,px,py,pz\n0,0,0,0\n");
  std::string text = minimal();
  text = text.substr(0, text.find("start ="));
  text += "file = \"session.csv\"\n";
  const Scene s = read_scene(write("s.toml", text));
  EXPECT_EQ(s.tools[0].trajectory.recorded_file, m_dir / "session.csv");
  EXPECT_TRUE(s.tools[0].trajectory.segments.empty());
}

TEST_F(SceneReaderTest, ASphereCutsOnlyWithTheVoxelModel) {
  // paper 002: the voxel model cuts with a stick tip (a sphere tool); without it, cutting needs a blade
  const std::string sphere = "kind = \"sphere\"\nradius = \"0.02 mm\"\n";
  EXPECT_THROW(read_scene(write("a.toml", minimal("geo = \"rect_prism.geo\"\nelement_size = 0.002\n", sphere))),
               SceneError);
  const std::string voxel =
      "[models.voxel]\nelastic_coefficient = \"20.0 N/m^2\"\nfriction_coefficient = 0.8\n"
      "damping_coefficient = \"0.5 N*s/m^2\"\ncritical_force_cutting = \"100 mN\"\ncritical_force_depth = 0.3\n"
      "advance_length = \"20 um\"\n";
  const Scene s = read_scene(write("b.toml", minimal("geo = \"rect_prism.geo\"\nelement_size = 0.002\n", sphere) + voxel));
  ASSERT_TRUE(s.voxel.has_value());
  EXPECT_EQ(s.voxel->grid, (std::array<int, 3>{10, 20, 20})); // default, paper 002 §4
  EXPECT_DOUBLE_EQ(s.voxel->critical_force_cutting, 0.1);
}

// A grasping stylus's compliant grasp: grasp_stiffness [N/m^3] read with its units (1.9 N/mm^3 =
// 1.9 / 1e-9 N/m^3 = 1.9e9 N/m^3 by the unit's definition); a value of the wrong dimension, a
// non-positive value or one without a grasp_radius refused at tools[0].grasp_stiffness.
TEST_F(SceneReaderTest, GraspStiffnessIsReadWithUnits) {
  auto grasping = [&](const std::string& extra) {
    std::string text = minimal("geo = \"rect_prism.geo\"\nelement_size = 0.002\n",
                               "kind = \"sphere\"\nradius = \"1 mm\"\n" + extra);
    const std::string from = "phenomena = [\"deformation\", \"cutting\"]";
    text.replace(text.find(from), from.size(), "phenomena = [\"deformation\"]");
    return write("s.toml", text);
  };
  const Scene tied = read_scene(grasping("grasp_radius = \"4 mm\"\n"));
  EXPECT_FALSE(tied.tools[0].grasp_stiffness.has_value()); // absent: the rigid tie
  const Scene s = read_scene(grasping("grasp_radius = \"4 mm\"\ngrasp_stiffness = \"1.9 N/mm^3\"\n"));
  ASSERT_TRUE(s.tools[0].grasp_stiffness.has_value());
  expect_si(*s.tools[0].grasp_stiffness, 1.9e9);
  expect_si(*read_scene(grasping("grasp_radius = \"4 mm\"\ngrasp_stiffness = \"1.9e9 N/m^3\"\n")).tools[0].grasp_stiffness,
            1.9e9);
  for (const std::string bad : {"grasp_radius = \"4 mm\"\ngrasp_stiffness = \"3 MPa\"\n",
                                "grasp_radius = \"4 mm\"\ngrasp_stiffness = \"0 N/m^3\"\n",
                                "grasp_stiffness = \"1.9e9 N/m^3\"\n"}) {
    SCOPED_TRACE(bad);
    const fs::path p = grasping(bad);
    try {
      (void)read_scene(p);
      ADD_FAILURE() << "no SceneError";
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind(p.string() + ":", 0), 0u) << m;
      EXPECT_NE(m.find(": tools[0].grasp_stiffness: "), std::string::npos) << m;
    }
  }
}

TEST_F(SceneReaderTest, ErrorsNameTheFileAsGiven) {
  const fs::path p = write("s.toml", minimal() + "[models]\nfracturre = 1\n");
  try {
    (void)read_scene(p);
    FAIL() << "no SceneError";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(p.string() + ":", 0), 0u) << m;
    EXPECT_NE(m.find(": models.fracturre: unknown key (expected one of: fracture, voxel, springs)"), std::string::npos) << m;
  }
}

TEST_F(SceneReaderTest, AMissingSceneFileIsASceneError) {
  EXPECT_THROW(read_scene(m_dir / "nope.toml"), SceneError);
}

TEST_F(SceneReaderTest, RangesAreChecked) {
  struct Case {
    std::string from, to, key;
  };
  const Case cases[] = {
      {"poisson_ratio = 0.3", "poisson_ratio = -1", "material.poisson_ratio"},
      {"density = 1000", "density = 0", "material.density"},
      {"fracture_toughness = \"0.2 kJ/m^2\"", "fracture_toughness = 0", "material.fracture_toughness"},
      {"cohesive_strength = \"0.5 N/mm^2\"", "cohesive_strength = \"-1 Pa\"", "material.cohesive_strength"},
      {"element_size = 0.002", "element_size = \"0 mm\"", "geometry.element_size"},
      {"element_size = 0.002", "element_size = 0.002\nelement_degree = 3", "geometry.element_degree"},
      {"element_size = 0.002", "element_size = 0.002\nelement_degree = \"2\"", "geometry.element_degree"},
      {"wedge_angle = 0.26", "wedge_angle = \"0 deg\"", "tools[0].wedge_angle"},
      {"rate = 2000", "rate = \"-1 kHz\"", "tools[0].trajectory.rate"},
      {"thickness = \"100 um\"", "thickness = \"1 MPa\"", "tools[0].thickness"},
      {"start = [0.02, 0, \"16 mm\"]", "start = [0.02, 0]", "tools[0].trajectory.start"},
      {"start = [0.02, 0, \"16 mm\"]", "start = [0.02, 0, \"16 s\"]", "tools[0].trajectory.start[2]"},
      {"phenomena = [\"deformation\", \"cutting\"]", "phenomena = []", "scene.phenomena"},
      {"phenomena = [\"deformation\", \"cutting\"]", "phenomena = [\"cutting\", \"cutting\"]", "scene.phenomena[1]"},
      {"name = \"t\"\n", "name = \"\"\n", "scene.name"},
      {"law = \"st-venant-kirchhoff\"", "law = \"mooney-rivlin\"", "material.law"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.to);
    std::string text = minimal();
    const auto at = text.find(c.from);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, c.from.size(), c.to);
    try {
      (void)read_scene(write("s.toml", text));
      ADD_FAILURE() << "no SceneError";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(": " + c.key + ": "), std::string::npos) << e.what();
    }
  }
}

} // namespace
} // namespace kerf
