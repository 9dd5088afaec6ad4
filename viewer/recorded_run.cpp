#include "viewer/recorded_run.hpp"

#include "experiments/models/run_model.hpp"
#include "experiments/records/content_hash.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "viewer/offline_stepping.hpp"
#include "viewer/viewed_model.hpp"
#include "viewer/von_mises.hpp"

#include <nlohmann/json.hpp>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataSet.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkPointData.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace kerf {

namespace {

/// The rows of one tool, in time order.
std::vector<const ProfileRow*> tool_rows(const ForceProfile& profile, const std::string& tool) {
  std::vector<const ProfileRow*> rows;
  for (const ProfileRow& r : profile.rows)
    if (r.tool == tool) rows.push_back(&r);
  return rows;
}

/// A tool's recorded positions as a sampled trajectory: the profile's times (uniform at the
/// run's rate), velocities by central differences (one-sided at the ends).
SampledTrajectory recorded_trajectory(const std::vector<const ProfileRow*>& rows, const std::filesystem::path& dir) {
  if (rows.size() < 2) throw std::runtime_error("viewer: " + dir.string() + "/profile.csv has fewer than two rows of a tool");
  SampledTrajectory t;
  t.rate = 1.0 / (rows[1]->t - rows[0]->t);
  if (!(t.rate > 0.0) || !std::isfinite(t.rate))
    throw std::runtime_error("viewer: " + dir.string() + "/profile.csv: times do not increase");
  for (std::size_t k = 0; k < rows.size(); ++k) {
    ToolState s;
    s.time = rows[k]->t;
    s.position = rows[k]->position;
    const std::size_t a = k == 0 ? 0 : k - 1, b = std::min(k + 1, rows.size() - 1);
    s.velocity = (rows[b]->position - rows[a]->position) / (rows[b]->t - rows[a]->t);
    t.samples.push_back(s);
    t.labels.emplace_back();
  }
  return t;
}

/// Cell data "von_mises" [Pa] of a deformed tetrahedral dataset with point data "displacement"
/// (rest = points − displacement), by von_mises_stress; cells that are not tetrahedra get 0.
void add_von_mises(vtkDataSet* body, const ElasticConstants& elastic) {
  vtkDataArray* u = body->GetPointData()->GetArray("displacement");
  if (!u || u->GetNumberOfComponents() != 3) return;
  const vtkIdType n = body->GetNumberOfPoints();
  Eigen::MatrixXd x(n, 3), rest(n, 3);
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3], d[3];
    body->GetPoint(i, p);
    u->GetTuple(i, d);
    for (int c = 0; c < 3; ++c) {
      x(i, c) = p[c];
      rest(i, c) = p[c] - d[c];
    }
  }
  const vtkIdType cells = body->GetNumberOfCells();
  Eigen::MatrixXi tets(cells, 4);
  std::vector<bool> is_tet(static_cast<std::size_t>(cells), false);
  auto ids = vtkSmartPointer<vtkIdList>::New();
  for (vtkIdType c = 0; c < cells; ++c) {
    body->GetCellPoints(c, ids);
    if (body->GetCellType(c) == VTK_TETRA && ids->GetNumberOfIds() == 4) {
      is_tet[static_cast<std::size_t>(c)] = true;
      for (int k = 0; k < 4; ++k) tets(c, k) = static_cast<int>(ids->GetId(k));
    } else {
      tets.row(c) << 0, 0, 0, 0; // degenerate: von_mises_stress gives 0
    }
  }
  const Eigen::VectorXd s = von_mises_stress(rest, x, tets, elastic.youngs_modulus, elastic.poisson_ratio);
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName("von_mises");
  array->SetNumberOfTuples(cells);
  for (vtkIdType c = 0; c < cells; ++c) array->SetValue(c, is_tet[static_cast<std::size_t>(c)] ? s(c) : 0.0);
  body->GetCellData()->AddArray(array);
}

} // namespace

RecordedRun::RecordedRun(const std::filesystem::path& dir, int frames) {
  namespace fs = std::filesystem;
  if (frames < 2) throw std::invalid_argument("viewer: a replay needs at least 2 frames");
  const fs::path manifest_file = dir / "manifest.json";
  std::ifstream in(manifest_file);
  if (!in) throw std::runtime_error("viewer: " + dir.string() + " is not a run directory (no manifest.json)");
  nlohmann::json manifest;
  try {
    manifest = nlohmann::json::parse(in);
    m_model_name = manifest.at("model").at("name").get<std::string>();
    const fs::path scene_file = manifest.at("scene").at("file").get<std::string>();
    if (!fs::exists(scene_file))
      throw std::runtime_error("the scene file " + scene_file.string() + " it was run on no longer exists");
    m_scene = std::make_unique<Scene>(read_scene(scene_file));
    if (manifest.at("scene").contains("sha256") && manifest["scene"]["sha256"].get<std::string>() != file_sha256(scene_file))
      std::fprintf(stderr, "kerf view: warning: %s changed since run %s (its SHA-256 differs)\n", scene_file.c_str(),
                   dir.c_str());
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error("viewer: " + manifest_file.string() + ": " + e.what());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("viewer: " + manifest_file.string() + ": " + e.what());
  }
  m_profile = read_profile_csv(dir / "profile.csv");
  if (m_profile.rows.empty()) throw std::runtime_error("viewer: " + (dir / "profile.csv").string() + " has no rows");
  m_label = fs::absolute(dir).lexically_normal().filename().string();
  if (m_label.empty()) m_label = fs::absolute(dir).lexically_normal().parent_path().filename().string();
  m_label += " (" + m_model_name + ")";
  for (const Tool& t : m_scene->tools) m_tools.push_back(t.name);
  for (const ProfileRow& r : m_profile.rows) {
    m_duration = std::max(m_duration, r.t);
    double radius = 0.0; // a sphere tool's whole sphere in view
    for (const Tool& t : m_scene->tools)
      if (t.name == r.tool && t.kind == Tool::Kind::sphere) radius = t.radius;
    m_bounds.extend(r.position - Eigen::Vector3d::Constant(radius));
    m_bounds.extend(r.position + Eigen::Vector3d::Constant(radius));
  }
  const std::vector<const ProfileRow*> first = tool_rows(m_profile, m_tools.front());
  if (first.empty()) throw std::runtime_error("viewer: " + dir.string() + "/profile.csv has no row of tool " + m_tools.front());
  for (const ProfileRow* r : first) {
    m_curve_t.push_back(r->t);
    m_curve_u.push_back((r->position - first.front()->position).norm());
    m_curve_f.push_back(r->force.norm());
  }

  const TetMesh mesh = scene_mesh(*m_scene);
  for (Eigen::Index i = 0; i < mesh.nodes.rows(); ++i) m_bounds.extend(mesh.nodes.row(i).transpose());
  // The run's own series, if it wrote one, and what its points are: the reference's fields.pvd
  // holds rest positions (deal.II's DataOut on the reference mapping); a series named in the
  // manifest says so in fields.points, "deformed" when it does not (the spring network's
  // springs.pvd, the one such series, has always held the moved mesh); a lone .pvd otherwise is
  // taken as ParaView's usual rest positions plus displacement.
  fs::path series;
  SeriesPoints points = SeriesPoints::rest;
  if (fs::exists(dir / "fields.pvd")) series = dir / "fields.pvd";
  else if (manifest.contains("fields") && manifest["fields"].is_object() && manifest["fields"].contains("series")) {
    const nlohmann::json& fields = manifest["fields"];
    series = dir / fields["series"].get<std::string>();
    points = SeriesPoints::deformed;
    if (fields.contains("points")) {
      const std::string p = fields["points"].is_string() ? fields["points"].get<std::string>() : std::string();
      if (p == "rest") points = SeriesPoints::rest;
      else if (p != "deformed")
        throw std::runtime_error("viewer: " + (dir / "manifest.json").string() + ": fields.points must be \"rest\" or \"deformed\"");
    }
  } else {
    std::vector<fs::path> found;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().extension() == ".pvd") found.push_back(e.path());
    if (found.size() == 1) series = found.front();
  }
  if (m_model_name == "reference" && series.empty())
    throw std::runtime_error("viewer: reference run " + dir.string() + " has no fields.pvd (run without --no-fields)");
  if (!series.empty()) {
    m_pvd = std::make_unique<PvdSeries>(series, points);
    m_series_name = series.filename().string();
    // The body at the series' last step in view too (torn pieces carried beyond the rest block).
    double b[6];
    m_pvd->deformed(m_pvd->times().size() - 1)->GetBounds(b);
    m_bounds.extend(Eigen::Vector3d(b[0], b[2], b[4]));
    m_bounds.extend(Eigen::Vector3d(b[1], b[3], b[5]));
    return;
  }

  // A fast model: rebuilt as the manifest says and re-stepped through the recorded positions.
  ModelOptions options;
  const nlohmann::json& parameters = manifest["model"]["parameters"];
  if (m_model_name == "springs" && parameters.contains("integrator"))
    options["integrator"] = parameters["integrator"].get<std::string>();
  BuiltModel built = make_model(m_model_name, *m_scene, mesh, options);
  std::unique_ptr<ModelAdapter> adapter = make_model_adapter(built, mesh);
  ViewedModel viewed(*built.model, *adapter, 1.0);
  // The scene's own trajectories when the profile recorded exactly those positions (a plain
  // `kerf run`: the same samples, velocities included), else the recorded positions.
  std::vector<SampledTrajectory> trajectories = sample_scene_trajectories(*m_scene);
  for (std::size_t i = 0; i < m_tools.size(); ++i) {
    const std::vector<const ProfileRow*> rows = tool_rows(m_profile, m_tools[i]);
    bool same = trajectories[i].samples.size() == rows.size();
    for (std::size_t k = 0; same && k < rows.size(); ++k)
      same = (trajectories[i].samples[k].position - rows[k]->position).norm() <= 1e-9 &&
             std::abs(trajectories[i].samples[k].time - rows[k]->t) <= 1e-9;
    if (!same) trajectories[i] = recorded_trajectory(rows, dir);
  }
  for (int k = 0; k < frames; ++k) m_frame_times.push_back(m_duration * k / (frames - 1));
  step_through(viewed, trajectories, m_frame_times, [&](const ViewFrame& f) {
    BodyGeometry g;
    adapter->geometry(f, g);
    m_frames.push_back(std::move(g));
    // The recorded force of the first tool at this time, against the re-stepped one.
    const std::size_t row = curve_index(f.time);
    if (f.tool_count > 0) m_replay_difference = std::max(m_replay_difference, (f.force[0].force - first[row]->force).norm());
  });
  m_frame_times.resize(m_frames.size());
  // Every snapshot's body in view too.
  for (const BodyGeometry& g : m_frames)
    for (Eigen::Index i = 0; i < g.points.rows(); ++i) m_bounds.extend(g.points.row(i).transpose());
}

RecordedRun::~RecordedRun() = default;

std::size_t RecordedRun::curve_index(double t) const {
  const auto it = std::upper_bound(m_curve_t.begin(), m_curve_t.end(), t + 1e-12);
  return it == m_curve_t.begin() ? 0 : static_cast<std::size_t>(it - m_curve_t.begin()) - 1;
}

void RecordedRun::show(double t, BodyView& view, bool text) {
  std::string status;
  double shown = t;
  if (m_pvd) {
    const std::size_t k = m_pvd->step_at(t);
    shown = m_pvd->times()[k];
    vtkDataSet* body = m_pvd->deformed(k);
    if (!body->GetPointData()->GetArray("von_mises") && !body->GetCellData()->GetArray("von_mises"))
      add_von_mises(body, {m_scene->material.youngs_modulus, m_scene->material.poisson_ratio});
    view.set_body(body);
    view.set_overlay(Eigen::MatrixXd(0, 3), Eigen::MatrixXi(0, 2));
    status = m_series_name + ": step " + std::to_string(k + 1) + " of " + std::to_string(m_pvd->times().size());
  } else {
    const auto it = std::upper_bound(m_frame_times.begin(), m_frame_times.end(), t + 1e-12);
    const std::size_t k = it == m_frame_times.begin() ? 0 : static_cast<std::size_t>(it - m_frame_times.begin()) - 1;
    shown = m_frame_times[k];
    const ElasticConstants elastic{m_scene->material.youngs_modulus, m_scene->material.poisson_ratio};
    view.set_body(body_dataset(m_frames[k], &elastic));
    view.set_overlay(m_frames[k].overlay_points, m_frames[k].overlay_lines);
    status = m_frames[k].status;
  }
  std::vector<Eigen::Vector3d> positions, forces;
  std::string lines;
  char line[256];
  std::snprintf(line, sizeof line, "%s   t = %.3f s\n", m_label.c_str(), shown);
  lines += line;
  for (const std::string& tool : m_tools) {
    const std::vector<const ProfileRow*> rows = tool_rows(m_profile, tool);
    const auto it = std::upper_bound(rows.begin(), rows.end(), shown + 1e-12, [](double v, const ProfileRow* r) { return v < r->t; });
    const ProfileRow* r = it == rows.begin() ? rows.front() : *(it - 1);
    positions.push_back(r->position);
    forces.push_back(r->force);
    std::snprintf(line, sizeof line, "%s: %s, |F| = %.3f N\n", tool.c_str(), std::string(to_string(r->mode)).c_str(),
                  r->force.norm());
    lines += line;
  }
  view.set_tools(positions, forces);
  view.set_text(text ? lines + status : std::string());
}

} // namespace kerf
