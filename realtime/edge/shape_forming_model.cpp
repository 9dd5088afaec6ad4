#include "realtime/edge/shape_forming_model.hpp"

#include "meshes/triangle_closest_point.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <thread>

namespace kerf {

TetMesh fragment_mesh(const CuttableBody& body, int fragment, std::vector<int>& cut_mesh_node) {
  const TetMesh& cut = body.mesh();
  if (fragment < 0 || fragment >= body.fragment_count())
    throw std::invalid_argument("fragment mesh: fragment " + std::to_string(fragment) + " does not exist");
  std::vector<int> local(static_cast<std::size_t>(cut.nodes.rows()), -1);
  std::vector<int> rows;
  cut_mesh_node.clear();
  for (Eigen::Index t = 0; t < cut.tets.rows(); ++t) {
    if (body.fragment_of_tet()[static_cast<std::size_t>(t)] != fragment) continue;
    rows.push_back(static_cast<int>(t));
    for (int k = 0; k < 4; ++k) {
      int& l = local[static_cast<std::size_t>(cut.tets(t, k))];
      if (l < 0) {
        l = static_cast<int>(cut_mesh_node.size());
        cut_mesh_node.push_back(cut.tets(t, k));
      }
    }
  }
  TetMesh m;
  m.nodes.resize(static_cast<Eigen::Index>(cut_mesh_node.size()), 3);
  for (std::size_t i = 0; i < cut_mesh_node.size(); ++i) m.nodes.row(static_cast<Eigen::Index>(i)) = cut.nodes.row(cut_mesh_node[i]);
  m.tets.resize(static_cast<Eigen::Index>(rows.size()), 4);
  std::vector<int> new_row(static_cast<std::size_t>(cut.tets.rows()), -1);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    new_row[static_cast<std::size_t>(rows[i])] = static_cast<int>(i);
    for (int k = 0; k < 4; ++k) m.tets(static_cast<Eigen::Index>(i), k) = local[static_cast<std::size_t>(cut.tets(rows[i], k))];
  }
  for (const VolumeGroup& g : cut.volume_groups) {
    VolumeGroup out{g.name, g.tag, {}};
    for (int t : g.tets)
      if (const int r = new_row[static_cast<std::size_t>(t)]; r >= 0) out.tets.push_back(r);
    std::sort(out.tets.begin(), out.tets.end());
    m.volume_groups.push_back(std::move(out));
  }
  // Surface groups: the fragment's boundary faces lying on a group's original triangles.
  const double size = (cut.nodes.colwise().maxCoeff() - cut.nodes.colwise().minCoeff()).norm();
  const double tolerance = 1e-9 * size;
  const Eigen::MatrixXi boundary = boundary_faces(m.tets);
  for (const SurfaceGroup& g : cut.surface_groups) {
    std::vector<Eigen::AlignedBox3d> boxes;
    for (Eigen::Index f = 0; f < g.triangles.rows(); ++f) {
      Eigen::AlignedBox3d b;
      for (int k = 0; k < 3; ++k) b.extend(Eigen::Vector3d(cut.nodes.row(g.triangles(f, k))));
      b.extend(b.min() - Eigen::Vector3d::Constant(tolerance));
      b.extend(b.max() + Eigen::Vector3d::Constant(tolerance));
      boxes.push_back(b);
    }
    auto on_group = [&](const Eigen::Vector3d& p) {
      for (Eigen::Index f = 0; f < g.triangles.rows(); ++f) {
        if (!boxes[static_cast<std::size_t>(f)].contains(p)) continue;
        const Eigen::Vector3d a = cut.nodes.row(g.triangles(f, 0)), b = cut.nodes.row(g.triangles(f, 1)),
                              c = cut.nodes.row(g.triangles(f, 2));
        if ((closest_point_on_triangle(p, a, b, c).point - p).norm() <= tolerance) return true;
      }
      return false;
    };
    std::vector<Eigen::Vector3i> faces;
    for (Eigen::Index f = 0; f < boundary.rows(); ++f) {
      bool all = true;
      for (int k = 0; k < 3 && all; ++k) all = on_group(m.nodes.row(boundary(f, k)).transpose());
      if (all) faces.emplace_back(boundary(f, 0), boundary(f, 1), boundary(f, 2));
    }
    SurfaceGroup out{g.name, g.tag, Eigen::MatrixXi(static_cast<Eigen::Index>(faces.size()), 3)};
    for (std::size_t i = 0; i < faces.size(); ++i) out.triangles.row(static_cast<Eigen::Index>(i)) = faces[i].transpose();
    m.surface_groups.push_back(std::move(out));
  }
  return m;
}

ShapeFormingModel::ShapeFormingModel(const TetMesh& mesh, ShapeFormingSetup setup) : m_setup(std::move(setup)) {
  if (m_setup.springs.styluses.size() != 1)
    throw std::invalid_argument("shape forming: the spring network takes exactly one stylus (tool 1)");
  if (!(m_setup.voxel_size > 0.0)) throw std::invalid_argument("shape forming: voxel size must be positive");
  m_edge = std::make_unique<DiscreteEdgeCuttingModel>(CollisionVoxels(mesh, m_setup.voxel_size, m_setup.regions), m_setup.edge);
  m_edge->attach_geometric_cut(
      std::make_unique<BackgroundCut>(mesh, m_setup.edge.blade, m_setup.cut, 4096,
                                      [this](const CuttableBody& body, const GeometricCutReport&) { build_stage(body); }),
      m_setup.record_spacing);
}

ShapeFormingModel::~ShapeFormingModel() {
  m_edge.reset(); // joins the worker before the stages it may be building go
}

void ShapeFormingModel::build_stage(const CuttableBody& body) {
  // The fragment the stylus touches: the tetrahedron whose centroid is nearest its start.
  const TetMesh& cut = body.mesh();
  const Eigen::Vector3d start = m_setup.springs.styluses.front().start;
  double best = std::numeric_limits<double>::infinity();
  int fragment = 0;
  for (Eigen::Index t = 0; t < cut.tets.rows(); ++t) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) centroid += 0.25 * Eigen::Vector3d(cut.nodes.row(cut.tets(t, k)));
    if (const double d = (centroid - start).squaredNorm(); d < best) {
      best = d;
      fragment = body.fragment_of_tet()[static_cast<std::size_t>(t)];
    }
  }
  auto stage = std::make_unique<FormingStage>();
  stage->fragment = fragment;
  stage->mesh = fragment_mesh(body, fragment, stage->cut_mesh_node);
  stage->cut_mesh = body.mesh();
  stage->fragment_of_tet = body.fragment_of_tet();
  stage->springs = std::make_unique<SpringNetworkModel>(stage->mesh, m_setup.springs);
  stage->embedding = std::make_unique<NetworkEmbedding>(stage->springs->network(), stage->mesh.nodes, EmbeddingScheme::trilinear);
  m_stages.push_back(std::move(stage));
  m_published.store(m_stages.back().get(), std::memory_order_release);
}

void ShapeFormingModel::reset() {
  m_edge->reset(); // waits for the worker, restores the uncut body
  m_published.store(nullptr, std::memory_order_release);
  m_active = nullptr;
  m_stages.clear();
}

void ShapeFormingModel::step(std::span<const ToolState> tools, double dt, std::span<ForceSample> forces) noexcept {
  if (tools.size() != 2 || forces.size() != 2) {
    for (ForceSample& f : forces) f = ForceSample{Eigen::Vector3d::Zero(), InteractionMode::no_contact, 0.0, true};
    return;
  }
  m_edge->step(tools.subspan(0, 1), dt, forces.subspan(0, 1));
  if (m_setup.wait_for_cut)
    while (m_edge->geometric_cut()->busy()) std::this_thread::yield();
  if (FormingStage* stage = m_published.load(std::memory_order_acquire); stage != m_active) m_active = stage;
  if (!m_active) {
    forces[1] = ForceSample{};
    return;
  }
  m_active->springs->step(tools.subspan(1, 1), dt, forces.subspan(1, 1));
}

TetMesh ShapeFormingModel::formed_mesh() {
  m_edge->finish_geometric_cut();
  TetMesh out = m_edge->geometric_cut()->body().mesh();
  if (const FormingStage* stage = m_active ? m_active : m_published.load(std::memory_order_acquire)) {
    Eigen::MatrixXd moved(stage->mesh.nodes.rows(), 3);
    stage->embedding->apply(stage->springs->network(), stage->springs->positions(), moved);
    for (std::size_t i = 0; i < stage->cut_mesh_node.size(); ++i)
      out.nodes.row(stage->cut_mesh_node[i]) = moved.row(static_cast<Eigen::Index>(i));
  }
  return out;
}

} // namespace kerf
