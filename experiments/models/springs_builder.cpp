// The spring-network model (paper 000 §2) built from a scene: one or two sphere styluses, the
// material's E, ν, ρ and damping, the scene's supports, tearing (at the material's cohesive
// strength, or [models.springs] tensile_limit) only if the scene declares it; the network's
// settings from [models.springs] (docs/scenes.md). Model option "integrator": explicit (force
// loops in single precision), explicit-double (in double precision), implicit, linear-implicit or
// static (overrides the scene's).

#include "experiments/models/model_builders.hpp"
#include "meshes/atomic_file.hpp"
#include "realtime/springs/network_embedding.hpp"
#include "realtime/springs/spring_network_model.hpp"
#include "realtime/springs/torn_tet_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

namespace kerf {

namespace {

/// The spring model as `kerf run` steps it, keeping what the .vtu series of the embedded fine
/// mesh needs (the embedded fine mesh, not the network, is what the .vtu series shows): every
/// `interval` [s] of simulated time the network's node positions and cell corners (which a tear
/// re-points), copied into frames allocated at construction, so `step` allocates nothing and
/// the cost the profile records stays the model's own plus one copy per frame. Not for the
/// haptic loop (the rig steps SpringNetworkModel itself).
class RecordedSpringModel final : public ToolModel {
public:
  RecordedSpringModel(std::unique_ptr<SpringNetworkModel> model, double interval, int frames)
      : m_model(std::move(model)), m_interval(interval) {
    const SpringNetwork& net = m_model->network();
    m_frames.resize(static_cast<std::size_t>(frames));
    for (Frame& f : m_frames) {
      f.x.resize(3, net.node_capacity());
      f.cells.reserve(net.cell_nodes.size());
    }
  }
  [[nodiscard]] std::string_view name() const override { return m_model->name(); }
  [[nodiscard]] int tool_count() const override { return m_model->tool_count(); }
  void reset() override {
    m_model->reset();
    m_time = 0.0;
    m_used = 0;
  }
  void step(std::span<const ToolState> tools, double dt, std::span<ForceSample> forces) noexcept override {
    m_model->step(tools, dt, forces);
    m_time += dt;
    if (m_used < m_frames.size() && m_time >= static_cast<double>(m_used) * m_interval) record(m_frames[m_used++]);
  }
  [[nodiscard]] SpringNetworkModel& model() { return *m_model; }

  /// DIR/springs.pvd and DIR/springs/frame_NNNN.vtu: the fine mesh, split along the network's
  /// pieces (split_tet_mesh) and moved by the trilinear embedding of each recorded frame, the
  /// last frame being the state after the last step; the points are the moved mesh (the
  /// manifest's fields.points = "deformed"), point data `displacement` = moved − rest [m], cell
  /// data `piece`, each .vtu through `write`. Returns the manifest's "fields" entry.
  nlohmann::json write_series(const TetMesh& mesh, const std::filesystem::path& dir, VtuWriter write) {
    std::vector<const Frame*> frames;
    for (std::size_t k = 0; k < m_used; ++k) frames.push_back(&m_frames[k]);
    Frame last;
    if (frames.empty() || frames.back()->time < m_time) { // the final state, if no frame fell on it
      record(last);
      frames.push_back(&last);
    }
    std::filesystem::create_directories(dir / "springs");
    SpringNetwork net = m_model->network(); // rest positions of every node, copies included
    std::vector<std::string> files;
    std::vector<double> times;
    std::unique_ptr<TornTetMesh> torn;
    std::unique_ptr<NetworkEmbedding> embedding;
    std::vector<std::array<int, 8>> torn_cells;
    for (std::size_t k = 0; k < frames.size(); ++k) {
      const Frame& f = *frames[k];
      if (!torn || f.cells != torn_cells) { // the network's division changed: split the fine mesh again
        net.cell_nodes = f.cells;
        net.node_count = f.node_count;
        torn = std::make_unique<TornTetMesh>(split_tet_mesh(mesh, net));
        embedding = std::make_unique<NetworkEmbedding>(net, torn->mesh.nodes, EmbeddingScheme::trilinear, &torn->host_cell);
        torn_cells = f.cells;
      }
      TetMesh moved = torn->mesh;
      embedding->apply(net, f.x, moved.nodes);
      Eigen::MatrixXd piece(moved.tets.rows(), 1);
      for (Eigen::Index t = 0; t < piece.rows(); ++t) piece(t, 0) = torn->piece[static_cast<std::size_t>(t)];
      char name[32];
      std::snprintf(name, sizeof name, "frame_%04zu.vtu", k);
      write(moved, dir / "springs" / name, {{"displacement", moved.nodes - torn->mesh.nodes}}, {{"piece", piece}});
      files.emplace_back(std::string("springs/") + name);
      times.push_back(f.time);
    }
    write_atomically(dir / "springs.pvd", [&](const std::filesystem::path& tmp) {
      std::ofstream out(tmp);
      out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
             "  <Collection>\n";
      out.precision(17);
      for (std::size_t k = 0; k < files.size(); ++k)
        out << "    <DataSet timestep=\"" << times[k] << "\" group=\"\" part=\"0\" file=\"" << files[k] << "\"/>\n";
      out << "  </Collection>\n</VTKFile>\n";
      out.flush();
      if (!out) throw std::runtime_error("springs: writing " + tmp.string() + " failed");
    });
    nlohmann::json j;
    j["series"] = "springs.pvd";
    j["points"] = "deformed"; // the .vtu points are the moved mesh; "displacement" = moved − rest
    j["frames"] = files.size();
    j["frame_interval_s"] = m_interval;
    j["embedding"] = "trilinear";
    j["pieces"] = m_model->pieces();
    j["vertex_splits"] = m_model->tears();
    return {{"fields", j}};
  }

private:
  struct Frame {
    double time = 0.0;
    Eigen::Matrix3Xd x;
    std::vector<std::array<int, 8>> cells;
    int node_count = 0;
  };
  /// Copies the model's state into `f` (no allocation once `f` is sized).
  void record(Frame& f) const noexcept {
    f.time = m_time;
    f.x = m_model->positions();
    f.cells = m_model->network().cell_nodes;
    f.node_count = m_model->network().node_count;
  }
  std::unique_ptr<SpringNetworkModel> m_model;
  double m_interval;
  std::vector<Frame> m_frames;
  std::size_t m_used = 0;
  double m_time = 0.0;
};

/// Frames of the .vtu series: one per 1/100 of the longest trajectory (and the final state).
constexpr int series_frames = 100;

} // namespace

void require_springs_inputs(const Scene& scene) {
  if (scene.tools.empty() || scene.tools.size() > 2)
    throw ModelMismatch("model springs needs one or two sphere (stylus) tools, or one blade; scene " + scene.name + " has " +
                        std::to_string(scene.tools.size()));
  for (const Tool& t : scene.tools)
    if (t.kind == Tool::Kind::blade && scene.tools.size() != 1)
      throw ModelMismatch("model springs takes a blade alone (the deformation phase of a one-blade cutting scene); "
                          "scene " + scene.name + " has " + std::to_string(scene.tools.size()) + " tools");
  if (scene.tools.front().kind == Tool::Kind::sphere && (scene.phenomena.contains(Phenomenon::cutting) ||
                                                          scene.phenomena.contains(Phenomenon::friction)))
    throw ModelMismatch("model springs represents cutting scenes only through a blade's deformation phase; scene " +
                        scene.name + " cuts with a sphere");
  if (scene.phenomena.contains(Phenomenon::tearing) && !(scene.material.cohesive_strength > 0.0) &&
      !(scene.springs && scene.springs->tensile_limit))
    throw ModelMismatch("model springs tears at [models.springs] tensile_limit or the material's cohesive_strength, neither of "
                        "which scene " + scene.name + " gives");
}

namespace {

/// Sets the integrator named `name` (a scene's [models.springs] integrator or `--integrator`):
/// "explicit-double" is symplectic Euler with its force loops in double precision ("explicit":
/// single precision, the default).
void set_integrator(SpringNetworkSetup& setup, const std::string& name) {
  const bool double_forces = name == "explicit-double";
  const auto integrator = double_forces ? SpringIntegrator::symplectic_euler : spring_integrator_from_string(name);
  if (!integrator)
    throw std::invalid_argument("model springs: integrator \"" + name +
                                "\" is not one of explicit, explicit-double, implicit, linear-implicit, static");
  setup.integrator = *integrator;
  setup.single_precision_forces = !double_forces;
}

} // namespace

namespace {

/// The network's setting from the scene (its material, supports and tools, [models.springs]) and
/// the command line's options (`integrator`).
SpringNetworkSetup springs_setup(const Scene& scene, const ModelOptions& options) {
  SpringNetworkSetup setup;
  const SpringsModelSettings settings = scene.springs.value_or(SpringsModelSettings{});
  if (settings.integrator) set_integrator(setup, *settings.integrator);
  for (const auto& [key, value] : options) {
    if (key != "integrator")
      throw std::invalid_argument("model springs: unknown option \"" + key + "\" (known: integrator)");
    set_integrator(setup, value);
  }
  const Material& m = scene.material;
  // A calibrated scene scales the modulus the spring constants are identified from ([models.springs]).
  setup.youngs_modulus = m.youngs_modulus * (scene.springs ? scene.springs->stiffness_scale : 1.0);
  setup.poisson_ratio = m.poisson_ratio;
  setup.density = m.density;
  setup.damping = settings.damping.value_or(m.damping);
  setup.volume_term = settings.volume_term.value_or(true);
  setup.cells = settings.cells.value_or(setup.cells);
  setup.cell_size = settings.cell_size.value_or(0.0);
  // The stylus grasps the scene's disc (Tool::grasp_radius a, the reference's region too): the
  // network nodes within the ball through the disc's rim, |x − c| <= (a² + r²)^½ of the tip centre
  // c (one tip radius r above the disc's centre); [models.springs] grasp_radius overrides it.
  setup.grasp_radius = settings.grasp_radius.value_or(0.0);
  if (!settings.grasp_radius)
    for (const Tool& t : scene.tools)
      if (t.kind == Tool::Kind::sphere && t.grasp_radius) {
        setup.grasp_radius = std::hypot(*t.grasp_radius, t.radius);
        break;
      }
  setup.tearing = scene.phenomena.contains(Phenomenon::tearing);
  setup.tensile_limit = setup.tearing ? settings.tensile_limit.value_or(m.cohesive_strength) : 0.0;
  for (const Support& s : scene.supports) setup.supports.push_back({s.surface, s.kind == Support::Kind::sliding});
  for (const Tool& t : scene.tools) {
    if (t.kind == Tool::Kind::blade) {
      setup.styluses.push_back({t.trajectory.start, 0.0, t.blade});
      // A blade crushes the cells under its edge: backward Euler unless the scene or the
      // command line says otherwise (the explicit limit shrinks with the crushed springs).
      if (!settings.integrator && options.find("integrator") == options.end()) setup.integrator = SpringIntegrator::implicit_euler;
    } else {
      // A compliant grasp (Tool::grasp_stiffness, the reference's elastic foundation): the same
      // layer k(r) = k (1 − r²/a²) on the same disc, lumped onto the network's face nodes.
      SpringStylus stylus{t.trajectory.start, t.radius};
      if (t.grasp_stiffness && t.grasp_radius) {
        stylus.grasp_stiffness = *t.grasp_stiffness;
        stylus.grasp_disc_radius = *t.grasp_radius;
      }
      setup.styluses.push_back(stylus);
    }
  }

  return setup;
}

/// The manifest's record of the network built from `setup`: integrator, lattice, spring
/// constants, grasp and tearing (docs/force-profile.md).
nlohmann::json springs_parameters(const Scene& scene, const SpringNetworkSetup& setup, const SpringNetworkModel& built) {
  const SpringNetwork& net = built.network();
  const CellIdentification& id = built.identification();
  nlohmann::json p;
  p["integrator"] = std::string(to_string(setup.integrator));
  if (setup.integrator == SpringIntegrator::symplectic_euler)
    p["force_precision"] = setup.single_precision_forces ? "single" : "double";
  p["cells_per_side"] = setup.cells;
  p["cell_size_m"] = net.block.cell_size;
  p["block_origin_m"] = nlohmann::json::array({net.block.origin.x(), net.block.origin.y(), net.block.origin.z()});
  p["kept_cells"] = net.cell_count();
  p["nodes"] = net.node_count;
  p["spring_constants_N_per_m"] = {{"edge", id.stiffness.edge}, {"face_diagonal", id.stiffness.face_diagonal},
                                   {"body_diagonal", id.stiffness.body_diagonal}};
  p["stiffness_scale"] = scene.springs ? scene.springs->stiffness_scale : 1.0;
  p["volume_modulus_Pa"] = id.stiffness.volume_modulus;
  p["network_poisson_ratio"] = id.poisson_ratio;
  p["bulk_modulus_error"] = id.bulk_modulus_error;
  p["damping_time_s"] = net.damping_time;
  p["volume_term"] = id.stiffness.volume_modulus > 0.0;
  // The rigid grasp's radius, where a stylus grasps rigidly.
  if (std::any_of(setup.styluses.begin(), setup.styluses.end(), [](const SpringStylus& t) { return !(t.grasp_stiffness > 0.0); }))
    p["grasp_radius_m"] = setup.grasp_radius > 0.0 ? nlohmann::json(setup.grasp_radius) : nlohmann::json("tip radius + h/2");
  // A compliant grasp: the layer's parameters and its lumped anchors, per stylus.
  for (std::size_t t = 0; t < setup.styluses.size(); ++t)
    if (const SpringStylus& stylus = setup.styluses[t]; stylus.grasp_stiffness > 0.0) {
      p["grasp"] = "compliant: k(r) = k (1 - r^2/a^2) on the disc of radius a around the contact point, lumped onto the network's "
                   "face nodes as anchor springs K_p = integral of N_p k(r) dA (docs/spring-network.md §3)";
      p["grasp_stiffness_N_per_m3"] = stylus.grasp_stiffness;
      p["grasp_disc_radius_m"] = stylus.grasp_disc_radius;
      p["grasp_anchors"] = nlohmann::json::array();
      for (int k = 0; k < built.tool_count(); ++k)
        p["grasp_anchors"].push_back({{"nodes", built.anchored_nodes(k)}, {"stiffness_sum_N_per_m", built.anchor_stiffness(k)}});
      break;
    }
  p["explicit_stability_limit_s"] = built.stability_limit();
  std::vector<int> attached;
  for (int t = 0; t < built.tool_count(); ++t) attached.push_back(built.attached_nodes(t));
  p["attached_nodes"] = attached;
  p["tearing"] = setup.tearing;
  if (setup.tearing) p["tensile_limit_Pa"] = setup.tensile_limit;
  return p;
}

} // namespace

BuiltModel build_springs_model(const Scene& scene, const TetMesh& mesh, const ModelOptions& options) {
  const SpringNetworkSetup setup = springs_setup(scene, options);
  double duration = 0.0;
  for (const Tool& t : scene.tools) duration = std::max(duration, sample(t.trajectory).duration());
  const double interval = std::max(duration, 1e-3) / series_frames;
  auto recorded = std::make_unique<RecordedSpringModel>(std::make_unique<SpringNetworkModel>(mesh, setup), interval, series_frames + 2);
  nlohmann::json p = springs_parameters(scene, setup, recorded->model());
  BuiltModel built{std::move(recorded), std::move(p)};
  auto* recording = static_cast<RecordedSpringModel*>(built.model.get());
  built.core = &recording->model();
  built.write_outputs = [recording, mesh](const std::filesystem::path& dir, VtuWriter write) {
    return recording->write_series(mesh, dir, write);
  };
  return built;
}

} // namespace kerf
