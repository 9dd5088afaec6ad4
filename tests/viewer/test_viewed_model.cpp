// ViewedModel and the model adapters, without rendering: a snapshot holds exactly the model's
// state at the step it was taken after; the render side's geometry follows the paper's rules
// (paper 000 §2.1: fine nodes outside the spring network stay at rest, fine nodes on network
// nodes move with them); a .pvd series reads back what kerf's own writer wrote.

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "meshes/vtu_writer.hpp"
#include "viewer/offline_stepping.hpp"
#include "viewer/pvd_series.hpp"
#include "viewer/springs_adapter.hpp"
#include "tests/realtime/springs/model_fixtures.hpp"
#include "viewer/viewed_model.hpp"

#include "tests/meshes/one_tetrahedron.hpp"

#include <gtest/gtest.h>
#include <vtkDataSet.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <unistd.h>

using namespace kerf;

/// clay_pull's spring network (tests/realtime/springs/model_fixtures.hpp: the scene's material,
/// support and stylus on a box mesh) and the scene's own trajectory.
struct ClayPull {
  TetMesh mesh = test::clay_pull_mesh();
  SpringNetworkModel model{mesh, test::clay_pull_setup(SpringIntegrator::symplectic_euler)};
  std::vector<SampledTrajectory> trajectory =
      sample_scene_trajectories(read_scene(std::string(KERF_SCENES_DIR) + "/clay_pull.toml"));
};

// The frame taken after a step is that step: network positions, forces and tool positions equal
// the model's own; the reader always gets the newest frame.
TEST(ViewedModel, SnapshotIsTheModelStateAfterTheStep) {
  ClayPull c;
  std::unique_ptr<ModelAdapter> adapter = make_model_adapter(c.model, c.mesh);
  ViewedModel viewed(c.model, *adapter, 1.0 / 60.0);
  const std::vector<SampledTrajectory>& t = c.trajectory;
  std::vector<ForceSample> forces(1);
  const double dt = 1.0 / t[0].rate;
  std::uint64_t taken = 0;
  for (std::size_t k = 0; k < 400; ++k) {
    viewed.step(std::span(&t[0].samples[k], 1), dt, forces);
    if (viewed.update()) {
      ++taken;
      const ViewFrame& f = viewed.frame();
      EXPECT_EQ(f.sequence, viewed.frames_published());
      EXPECT_EQ(f.time, t[0].samples[k].time);
      EXPECT_EQ(f.tool_position[0], t[0].samples[k].position);
      EXPECT_EQ(f.force[0].force, forces[0].force);
      const int n = c.model.network().node_count;
      ASSERT_EQ(f.model.point_count, n);
      EXPECT_EQ(Eigen::Matrix3Xd(f.model.points.leftCols(n)), Eigen::Matrix3Xd(c.model.positions().leftCols(n)));
    }
  }
  // One frame per 1/60 s of model time: 400 ms at 1 kHz gives one every 17 ms (the first step
  // publishes at once), 24 in all.
  EXPECT_EQ(taken, 24u);
}

/// An adapter whose snapshot takes a lock the render side may hold (what the triple buffer
/// avoids): the springs adapter's capture under `lock`.
/// `capturing` is raised just before the lock is taken, so the render side knows the snapshot
/// has reached it.
class LockingAdapter final : public ModelAdapter {
public:
  LockingAdapter(ModelAdapter& inner, std::mutex& lock, std::atomic<bool>& capturing)
      : m_inner(inner), m_lock(lock), m_capturing(capturing) {}
  void reserve(ModelState& state) const override { m_inner.reserve(state); }
  void capture(ModelState& state) const noexcept override {
    m_capturing.store(true);
    const std::lock_guard<std::mutex> hold(m_lock);
    m_inner.capture(state);
  }
  void geometry(const ViewFrame& frame, BodyGeometry& out) override { m_inner.geometry(frame, out); }
  [[nodiscard]] std::string_view overlay_name() const override { return m_inner.overlay_name(); }

private:
  ModelAdapter& m_inner;
  std::mutex& m_lock;
  std::atomic<bool>& m_capturing;
};

/// The scheduler state of thread `tid` of this process ('R' running, 'S' sleeping, ...): the
/// third field of /proc/self/task/TID/stat (proc(5)); '?' when it cannot be read.
static char thread_state(pid_t tid) {
  std::ifstream stat("/proc/self/task/" + std::to_string(tid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return '?';
  const std::size_t name_end = line.rfind(')'); // the command name may hold spaces
  return name_end + 2 < line.size() ? line[name_end + 2] : '?';
}

// The count the live view's test relies on (ViewedModel::blocked_snapshots): a snapshot that
// only copies into the wait-free triple buffer never waits, while one that needs a lock held
// elsewhere (here by a "render" thread) waits and is counted — the thread's voluntary context
// switch, whatever the machine's load. The render thread lets go only once the stepping thread
// is asleep on the lock (its /proc state 'S' after it reached the capture), so the wait is
// certain however long the model's step before the capture takes (under a sanitizer on a loaded
// machine it took longer than a fixed hold).
TEST(ViewedModel, ASnapshotThatWaitsIsCounted) {
  ClayPull c;
  std::unique_ptr<ModelAdapter> adapter = make_model_adapter(c.model, c.mesh);
  std::vector<ForceSample> forces(1);
  const double dt = 1.0 / c.trajectory[0].rate;
  {
    ViewedModel viewed(c.model, *adapter, dt); // a snapshot at every step
    for (std::size_t k = 0; k < 200; ++k) viewed.step(std::span(&c.trajectory[0].samples[k], 1), dt, forces);
    EXPECT_EQ(viewed.frames_published(), 200u);
    EXPECT_EQ(viewed.blocked_snapshots(), 0u);
  }
  std::mutex lock;
  std::atomic<bool> capturing{false};
  LockingAdapter locking(*adapter, lock, capturing);
  ViewedModel viewed(c.model, locking, dt);
  std::atomic<bool> held{false};
  std::atomic<bool> saw_it_sleep{false};
  const pid_t stepping_thread = gettid();
  std::thread render([&] {
    const std::lock_guard<std::mutex> hold(lock);
    held.store(true);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!capturing.load() && std::chrono::steady_clock::now() < give_up) std::this_thread::yield();
    while (std::chrono::steady_clock::now() < give_up) {
      if (thread_state(stepping_thread) == 'S') {
        saw_it_sleep.store(true);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  while (!held.load()) std::this_thread::yield();
  viewed.step(std::span(&c.trajectory[0].samples[0], 1), dt, forces); // waits for the render thread
  render.join();
  ASSERT_TRUE(saw_it_sleep.load()) << "the stepping thread never slept on the held lock within 60 s";
  EXPECT_EQ(viewed.frames_published(), 1u);
  EXPECT_EQ(viewed.blocked_snapshots(), 1u);
}

// Paper 000 §2.1: the fine mesh follows the network by interpolation inside the network's cells
// and keeps its rest position outside them; a fine node at a network node's rest position moves
// exactly with that node (the Coons interpolant reproduces its nodes).
TEST(SpringsAdapter, FineMeshFollowsTheNetworkInsideAndRestsOutside) {
  ClayPull c;
  std::unique_ptr<ModelAdapter> adapter = make_model_adapter(c.model, c.mesh);
  ViewedModel viewed(c.model, *adapter, 1.0);
  const std::array<double, 1> times{1.6};
  BodyGeometry g;
  step_through(viewed, c.trajectory, times, [&](const ViewFrame& f) { adapter->geometry(f, g); });
  const SpringNetwork& net = c.model.network();
  const Eigen::Vector3d lo = net.block.origin;
  const Eigen::Vector3d hi = lo + net.block.cell_size * net.block.cells.cast<double>();
  int outside = 0, on_nodes = 0;
  double largest = 0.0;
  for (Eigen::Index i = 0; i < g.rest.rows(); ++i) {
    const Eigen::Vector3d X = g.rest.row(i).transpose();
    const Eigen::Vector3d u = (g.points.row(i) - g.rest.row(i)).transpose();
    largest = std::max(largest, u.norm());
    if ((X.array() < lo.array() - 1e-9).any() || (X.array() > hi.array() + 1e-9).any()) {
      ++outside;
      EXPECT_EQ(u.norm(), 0.0) << "fine node " << i << " outside the network moved";
      continue;
    }
    for (int n = 0; n < net.node_count; ++n)
      if ((net.rest.col(n) - X).norm() < 1e-12) {
        ++on_nodes;
        EXPECT_LT((g.points.row(i).transpose() - c.model.positions().col(n)).norm(), 1e-12);
      }
  }
  EXPECT_GT(outside, 20);
  EXPECT_GT(on_nodes, 10);
  // The stylus pulled 6 mm: the body moved, by no more than the stylus did.
  EXPECT_GT(largest, 1e-3);
  EXPECT_LT(largest, 6e-3 + 1e-4);
}

// Paper 000 §2.2 (Fig. 5): once the network tears, the fine mesh is divided along the exposed cell
// faces and each side follows the cells of its own piece. clay_tear
// (experiments/scenes/clay_tear.toml: its gmsh mesh, whose unstructured tetrahedra cross the
// network's cell faces, and the network settings of tests/realtime/springs/test_tearing.cpp,
// the scene's own): the styluses pull the 60 mm bar apart by 10 mm each
// (2 s), then hold (1 s); the bar tears near its mid-plane x = 30 mm and each piece, free on its
// table, follows its stylus: a translation by 10 mm along -x (left) or +x (right). So every fine
// node drawn at t = 3 s, the tear's neighbourhood included, has moved about 10 mm; the tear runs
// along cell faces (vertex splitting, h = 5 mm) within a cell of the mid-plane, so nodes left of
// x = 25 mm moved along -x and nodes right of x = 35 mm along +x; none is left behind at rest.
TEST(SpringsAdapter, TornBodyMovesWithItsPieces) {
  const Scene scene = read_scene(std::string(KERF_SCENES_DIR) + "/clay_tear.toml");
  const TetMesh mesh = scene_mesh(scene);
  SpringNetworkSetup s = test::clay_tear_setup(SpringIntegrator::implicit_euler);
  s.cell_size = 0.005;
  SpringNetworkModel model(mesh, s);
  std::unique_ptr<ModelAdapter> adapter = make_model_adapter(model, mesh);
  ViewedModel viewed(model, *adapter, 1.0);
  const std::array<double, 1> times{3.0};
  BodyGeometry g;
  step_through(viewed, sample_scene_trajectories(scene), times,
               [&](const ViewFrame& f) { adapter->geometry(f, g); });
  ASSERT_EQ(model.pieces(), 2) << "clay_tear did not tear (" << model.tears() << " vertex splits)";
  ASSERT_GT(g.rest.rows(), mesh.nodes.rows()) << "the drawn body should be the split mesh (nodes duplicated)";
  int left = 0, right = 0, behind = 0;
  for (Eigen::Index i = 0; i < g.rest.rows(); ++i) {
    const Eigen::Vector3d u = (g.points.row(i) - g.rest.row(i)).transpose();
    if (u.norm() < 5e-3) ++behind;
    EXPECT_NEAR(u.norm(), 0.010, 1e-3) << "fine node " << i << " at x = " << g.rest(i, 0);
    if (g.rest(i, 0) < 0.025 - 1e-6) {
      ++left;
      EXPECT_LT(u.x(), -0.009) << "fine node " << i;
    } else if (g.rest(i, 0) > 0.035 + 1e-6) {
      ++right;
      EXPECT_GT(u.x(), 0.009) << "fine node " << i;
    }
  }
  EXPECT_EQ(behind, 0) << "fine nodes left at rest behind their piece";
  EXPECT_GT(left, 100);
  EXPECT_GT(right, 100);
}

// The shape-forming model (clay_cut_apart.toml, model edge: a blade cuts a 10 mm cube off a
// 30 x 10 x 10 mm bar at x = 10 mm, then the stylus drags the cube 5 mm along -x on the smooth
// plate and holds it 1 s). Expected, from the scene alone: before the cut reaches the model, the
// body at rest (the scene mesh); once cut, the body as the cut left it (more nodes: the crack's
// copies) with no node moved yet; at the end the cube (rest x < 10 mm) translated by the
// stylus's (-5, 0, 0) mm — free on the plate, held by nothing else, its network covering all of
// it (8 cells of 1.25 mm), the 1 s hold damping its recoil — and the bar (rest x > 10 mm) in no
// network, every node exactly where it was.
TEST(ShapeFormingAdapter, DrawsTheCutBodyWithThePieceUnderTheStylusMoved) {
  const Scene scene = read_scene(std::string(KERF_SCENES_DIR) + "/clay_cut_apart.toml");
  const TetMesh mesh = scene_mesh(scene);
  const BuiltModel built = make_model("edge", scene, mesh);
  std::unique_ptr<ModelAdapter> adapter = make_model_adapter(built, mesh);
  ViewedModel viewed(*built.model, *adapter, 1.0);
  const std::array<double, 3> times{0.5, 1.75, 3.8};
  std::vector<BodyGeometry> g;
  step_through(viewed, sample_scene_trajectories(scene), times, [&](const ViewFrame& f) {
    g.emplace_back();
    adapter->geometry(f, g.back());
  });
  ASSERT_EQ(g.size(), 3u);
  EXPECT_EQ(g[0].points, mesh.nodes) << "nothing is cut at 0.5 s (the blade is 4 mm deep)";
  EXPECT_EQ(g[0].tets, mesh.tets);
  ASSERT_GT(g[1].rest.rows(), mesh.nodes.rows()) << "the cut should have opened (node copies on the crack)";
  // (Up to the rounding of the trilinear embedding of nodes at rest: 1e-9 m is a millionth of a
  // cell.)
  EXPECT_LT((g[1].points - g[1].rest).cwiseAbs().maxCoeff(), 1e-9) << "cut, not yet dragged: nothing moved";
  ASSERT_EQ(g[2].rest.rows(), g[1].rest.rows());
  int cube = 0, bar = 0;
  for (Eigen::Index i = 0; i < g[2].rest.rows(); ++i) {
    const Eigen::Vector3d u = (g[2].points.row(i) - g[2].rest.row(i)).transpose();
    if (g[2].rest(i, 0) < 0.010 - 1e-9) {
      ++cube;
      EXPECT_NEAR((u - Eigen::Vector3d(-0.005, 0.0, 0.0)).norm(), 0.0, 1e-6) << "cube node " << i;
    } else if (g[2].rest(i, 0) > 0.010 + 1e-9) {
      ++bar;
      EXPECT_EQ(u.norm(), 0.0) << "bar node " << i;
    }
  }
  EXPECT_GT(cube, 100);
  EXPECT_GT(bar, 100);
}

// What `kerf view SCENE --model M` and the replay of a run get from the catalogue: each model is
// read by its own adapter (the overlay it draws names it), also where a builder wraps the model
// proper for `kerf run`'s recording (BuiltModel::core_model()); a model without an adapter would
// show its body at rest, which for these would hide what they do (edge on a scene with a blade
// and a stylus is the shape-forming model, paper 000 §4).
TEST(ModelAdapter, EachCatalogueModelIsReadByItsOwnAdapter) {
  const std::vector<std::array<std::string, 3>> cases{{"clay_pull", "springs", "spring network"},
                                                      {"sponge_cut_constant", "voxel", "voxel grid"},
                                                      {"potato_rect_cut", "fracture", "crack"},
                                                      {"potato_rect_cut", "edge", "discrete edge"},
                                                      {"clay_cut_apart", "edge", "discrete edge, spring network"}};
  for (const auto& [scene_name, model, overlay] : cases) {
    const Scene scene = read_scene(std::string(KERF_SCENES_DIR) + "/" + scene_name + ".toml");
    const TetMesh mesh = scene_mesh(scene);
    const BuiltModel built = make_model(model, scene, mesh);
    EXPECT_EQ(make_model_adapter(built, mesh)->overlay_name(), overlay) << scene_name << " / " << model;
  }
}

// A .pvd written like the reference's (kerf's VTU writer, a displacement field, steps listed
// out of order) reads back sorted, with points moved by exactly the displacement; the same
// files read as a series of deformed positions keep their points as written.
TEST(PvdSeries, ReadsStepsAtTheirDeformedPositions) {
  const auto dir = std::filesystem::temp_directory_path() / ("kerf_test_pvd_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "fields");
  const TetMesh mesh = test::one_tetrahedron();
  for (int k = 0; k < 2; ++k) {
    Eigen::MatrixXd u = Eigen::MatrixXd::Zero(4, 3);
    u.col(2).setConstant(0.5 * k);
    write_vtu(mesh, dir / "fields" / ("step_" + std::to_string(k) + ".vtu"), {{"displacement", u}});
  }
  {
    std::ofstream pvd(dir / "fields.pvd");
    pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n"
           "<DataSet timestep=\"2.5\" file=\"fields/step_1.vtu\"/>\n<DataSet timestep=\"0\" file=\"fields/step_0.vtu\"/>\n"
           "</Collection>\n</VTKFile>\n";
  }
  // Written at rest positions (as the reference's fields.pvd): shown at X + u.
  PvdSeries series(dir / "fields.pvd", SeriesPoints::rest);
  ASSERT_EQ(series.times().size(), 2u);
  EXPECT_EQ(series.times()[0], 0.0);
  EXPECT_EQ(series.times()[1], 2.5);
  EXPECT_EQ(series.step_at(-1.0), 0u);
  EXPECT_EQ(series.step_at(2.4), 0u);
  EXPECT_EQ(series.step_at(2.5), 1u);
  vtkDataSet* moved = series.deformed(1);
  ASSERT_EQ(moved->GetNumberOfPoints(), 4);
  for (vtkIdType i = 0; i < 4; ++i) {
    double p[3];
    moved->GetPoint(i, p);
    EXPECT_DOUBLE_EQ(p[2], mesh.nodes(i, 2) + 0.5);
  }
  // The same files read as a series of deformed positions (as the spring network's springs.pvd
  // writes them): shown where they are, not moved by u a second time.
  PvdSeries as_written(dir / "fields.pvd", SeriesPoints::deformed);
  vtkDataSet* kept = as_written.deformed(1);
  ASSERT_EQ(kept->GetNumberOfPoints(), 4);
  for (vtkIdType i = 0; i < 4; ++i) {
    double p[3];
    kept->GetPoint(i, p);
    EXPECT_DOUBLE_EQ(p[2], mesh.nodes(i, 2));
  }
  EXPECT_THROW(PvdSeries(dir / "missing.pvd", SeriesPoints::rest), std::runtime_error);
  std::filesystem::remove_all(dir);
}
