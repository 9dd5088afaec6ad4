// A scene meshes to the same mesh whatever another thread of the process does meanwhile: gmsh
// seeds and draws from the C library's rand(), and so does METIS inside CHOLMOD's analysis
// (meshes/c_random_generator.hpp). clay_pull's reference mesh at 5 mm (its study level -1) is made
// alone, then again while a second thread keeps ordering a 3-D grid Laplacian with CHOLMOD (whose
// fill under AMD is large enough that METIS is tried): every mesh must equal the first, node for
// node. Without the shared lock a study that solved two references at once published a level-1
// clay_pull mesh with 793 nodes where the scene alone meshes to 794.

#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "experiments/study/reference_cache.hpp"
#include "reference/sparse_direct.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

using namespace kerf;
namespace fs = std::filesystem;

namespace {

/// The 7-point Laplacian's pattern on an n³ grid, rows sorted: a matrix whose Cholesky factor
/// fills enough for CHOLMOD to try METIS after AMD.
reference::SparseDirect grid_laplacian_pattern(int n) {
  std::vector<std::int64_t> row_start{0}, columns;
  auto index = [n](int i, int j, int k) { return static_cast<std::int64_t>((k * n + j) * n + i); };
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        if (k > 0) columns.push_back(index(i, j, k - 1));
        if (j > 0) columns.push_back(index(i, j - 1, k));
        if (i > 0) columns.push_back(index(i - 1, j, k));
        columns.push_back(index(i, j, k));
        if (i + 1 < n) columns.push_back(index(i + 1, j, k));
        if (j + 1 < n) columns.push_back(index(i, j + 1, k));
        if (k + 1 < n) columns.push_back(index(i, j, k + 1));
        row_start.push_back(static_cast<std::int64_t>(columns.size()));
      }
  return reference::SparseDirect(static_cast<std::size_t>(n) * n * n, std::move(row_start), std::move(columns));
}

} // namespace

TEST(MeshBesideOrdering, TheSameSceneMeshesTheSameWhileCholmodOrdersBesideIt) {
  const Scene scene = study_reference_scene(read_scene(fs::path(KERF_SOURCE_DIR) / "experiments" / "scenes" / "clay_pull.toml"), -1);
  const TetMesh alone = scene_mesh(scene, MeshPurpose::reference);
  ASSERT_GT(alone.nodes.rows(), 0);

  std::atomic<bool> done{false};
  std::atomic<int> orderings{0};
  std::thread beside([&] {
    while (!done.load()) {
      reference::SparseDirect pattern = grid_laplacian_pattern(24);
      EXPECT_GT(pattern.cholesky_factor_entries(), 0.0);
      ++orderings;
    }
  });
  for (int k = 0; k < 4; ++k) {
    const TetMesh again = scene_mesh(scene, MeshPurpose::reference);
    ASSERT_EQ(again.nodes.rows(), alone.nodes.rows()) << "mesh " << k;
    ASSERT_EQ(again.tets.rows(), alone.tets.rows()) << "mesh " << k;
    EXPECT_EQ(again.nodes, alone.nodes) << "mesh " << k;
    EXPECT_EQ(again.tets, alone.tets) << "mesh " << k;
  }
  done = true;
  beside.join();
  EXPECT_GT(orderings.load(), 0); // the second thread did order meanwhile
}
