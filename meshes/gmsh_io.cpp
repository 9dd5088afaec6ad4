#include "meshes/gmsh_io.hpp"
#include "meshes/c_random_generator.hpp"

#include "meshes/atomic_file.hpp"
#include "meshes/mesh_error.hpp"
#include "meshes/tet_quality.hpp"

#include <gmsh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <map>
#include <mutex>
#include <numbers>
#include <numeric>
#include <set>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace kerf {

namespace {

namespace fs = std::filesystem;

/// gmsh element types (gmsh reference manual, "MSH file format").
constexpr int k_gmsh_triangle = 2;
constexpr int k_gmsh_tetrahedron = 4;

/// Prefix of the ONELAB names under which kerf's .geo files declare their parameters:
/// `DefineConstant[ NAME = {default, Name "Parameters/NAME"} ]`.
constexpr std::string_view k_parameter_prefix = "Parameters/";


/// Initialises gmsh once per process (thread-safe function-local static) and configures it to be
/// silent: messages go to gmsh's logger, which GmshSession reads back to build MeshError
/// messages. General.AbortOnError = 0 because gmsh 4.8 throws from inside its .geo parser on an
/// error and then leaves the parser in a state where the next file yields an empty model; with 0
/// the parse finishes, the error is logged, and GmshSession turns it into a MeshError.
/// gmsh::finalize() is deliberately never called: the library stays usable for the whole process
/// and tearing it down during static destruction would race gmsh's own statics.
void ensure_gmsh_initialized() {
  static const bool initialized = [] {
    gmsh::initialize(0, nullptr, /*readConfigFiles=*/false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 2); // errors and warnings reach the logger
    gmsh::option::setNumber("General.AbortOnError", 0);
    gmsh::option::setNumber("General.NumThreads", 1);
    return true;
  }();
  (void)initialized;
}

/// One use of gmsh: holds the lock, starts from an empty model and an empty ONELAB database,
/// records gmsh's messages, and turns failures (exceptions or logged errors) into MeshError
/// naming the file.
class GmshSession {
public:
  explicit GmshSession(std::string file)
      : m_lock(c_random_generator_mutex()), m_file(std::move(file)) {
    ensure_gmsh_initialized();
    reset();
    gmsh::logger::start();
  }
  ~GmshSession() {
    try {
      gmsh::logger::stop();
      gmsh::clear();
    } catch (...) {
      // Nothing sensible to do in a destructor; the next session clears again.
    }
  }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

  /// Empty model and ONELAB database (stale ONELAB values would override a .geo's defaults), and
  /// the meshing options back at gmsh's defaults: gmsh::clear() empties the model but keeps the
  /// options, and a .geo that grades its mesh with a size field turns Mesh.MeshSizeFromPoints and
  /// Mesh.MeshSizeExtendFromBoundary off (meshes/geo/*.geo) — without this every later mesh of the
  /// process was made without them, and a scene meshed differently after a graded one (the wedge's
  /// 1 441 nodes became 1 363; test SceneMeshHistory).
  static void reset() {
    gmsh::clear();
    gmsh::onelab::clear();
    for (const auto& [name, value] : default_mesh_options()) gmsh::option::setNumber(name, value);
  }

  /// The meshing options a .geo of meshes/geo or kerf's own code sets, with gmsh's values for them
  /// when it was initialised.
  static const std::vector<std::pair<std::string, double>>& default_mesh_options() {
    static const std::vector<std::pair<std::string, double>> defaults = [] {
      std::vector<std::pair<std::string, double>> d;
      for (const char* name : {"Mesh.MeshSizeFromPoints", "Mesh.MeshSizeExtendFromBoundary", "Mesh.MeshSizeFromCurvature",
                               "Mesh.MeshSizeMax", "Mesh.MeshSizeMin", "Mesh.MeshSizeFactor", "Mesh.ElementOrder", "Mesh.Optimize",
                               "Mesh.OptimizeNetgen", "Mesh.Algorithm", "Mesh.Algorithm3D", "Mesh.RandomSeed", "Mesh.RandomFactor",
                               "Mesh.MshFileVersion", "Mesh.Binary", "Mesh.SaveAll", "Mesh.SaveParametric"}) {
        double value = 0.0;
        gmsh::option::getNumber(name, value);
        d.emplace_back(name, value);
      }
      return d;
    }();
    return defaults;
  }

  /// Runs `action`; throws MeshError("<file>: <what>: <gmsh errors>") if it throws or if gmsh
  /// logged an error meanwhile.
  template <class Action> void run(const std::string& what, Action&& action) {
    std::string exception_text;
    try {
      action();
    } catch (const MeshError&) {
      throw;
    } catch (const std::string& text) { // gmsh 4.8 throws std::string
      exception_text = text;
    } catch (const std::exception& e) {
      exception_text = e.what();
    } catch (...) {
      exception_text = "unknown gmsh exception";
    }
    std::vector<std::string> log;
    gmsh::logger::get(log);
    gmsh::logger::stop(); // stop + start empties the log for the next step
    gmsh::logger::start();
    std::string errors;
    for (const auto& line : log)
      if (line.rfind("Error", 0) == 0) errors += (errors.empty() ? "" : "; ") + line;
    if (!exception_text.empty() && errors.find(exception_text) == std::string::npos)
      errors += (errors.empty() ? "" : "; ") + exception_text;
    if (!errors.empty()) throw MeshError(m_file + ": " + what + " failed: " + errors);
  }

private:
  // gmsh keeps one global model and is not thread-safe, and it seeds and draws from the C
  // library's rand(): one lock serves both (meshes/c_random_generator.hpp).
  std::lock_guard<std::mutex> m_lock;
  std::string m_file;
};

void require_file(const fs::path& path, const char* kind) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) throw MeshError(path.string() + ": no such " + kind + " file");
}

void require_element_size(const fs::path& path, double element_size) {
  if (!(element_size > 0.0) || !std::isfinite(element_size))
    throw MeshError(path.string() + ": element size must be a positive number of metres, got " +
                    std::to_string(element_size));
}

/// Options for first-order, optimised tetrahedra of target size `h` (in the model's units).
void set_volume_meshing_options(double h) {
  gmsh::option::setNumber("Mesh.MeshSizeMax", h);
  gmsh::option::setNumber("Mesh.MeshSizeMin", 0.0);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::option::setNumber("Mesh.ElementOrder", 1);
  gmsh::option::setNumber("Mesh.Optimize", 1);
  gmsh::option::setNumber("Mesh.Algorithm3D", 1); // Delaunay
}

/// Whether extraction orients every tetrahedron positively (gmsh's own meshes, whose orientation
/// convention is not kerf's) or keeps the file's node order (a mesh read from a file).
enum class TetOrientation { make_positive, as_stored };

/// Reads the current gmsh model's mesh into a TetMesh: nodes used by a tetrahedron or a physical
/// triangle, renumbered compactly in ascending gmsh node-tag order; tetrahedra in ascending
/// element-tag order, each positively oriented if `orientation` says so; every physical volume (its tetrahedra) and
/// physical surface (its triangles, ascending element tag). Unnamed groups: "physical_<tag>".
TetMesh extract_tet_mesh(const std::string& file, TetOrientation orientation) {
  std::vector<int> volume_types;
  gmsh::model::mesh::getElementTypes(volume_types, 3);
  for (const int type : volume_types)
    if (type != k_gmsh_tetrahedron) {
      std::string name;
      int dim = 0, order = 0, nodes = 0, primary = 0;
      std::vector<double> local;
      gmsh::model::mesh::getElementProperties(type, name, dim, order, nodes, local, primary);
      throw MeshError(file + ": holds volume elements of type '" + name +
                      "'; kerf reads only first-order tetrahedra (gmsh type 4)");
    }

  std::vector<std::size_t> tet_tags;
  std::vector<std::size_t> tet_nodes;
  gmsh::model::mesh::getElementsByType(k_gmsh_tetrahedron, tet_tags, tet_nodes);
  if (tet_tags.empty()) throw MeshError(file + ": the mesh holds no tetrahedra");

  // Tetrahedra in ascending element-tag order.
  std::vector<std::size_t> order(tet_tags.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return tet_tags[a] < tet_tags[b]; });
  std::vector<std::size_t> sorted_tet_tags(tet_tags.size());
  for (std::size_t i = 0; i < order.size(); ++i) sorted_tet_tags[i] = tet_tags[order[i]];
  auto tet_index_of = [&](std::size_t tag) {
    const auto it = std::lower_bound(sorted_tet_tags.begin(), sorted_tet_tags.end(), tag);
    if (it == sorted_tet_tags.end() || *it != tag)
      throw MeshError(file + ": element " + std::to_string(tag) + " is not a tetrahedron of the mesh");
    return static_cast<int>(it - sorted_tet_tags.begin());
  };

  struct RawSurfaceGroup {
    std::string name;
    int tag;
    std::vector<std::pair<std::size_t, std::array<std::size_t, 3>>> triangles; ///< element tag, node tags
  };
  TetMesh mesh;
  std::vector<RawSurfaceGroup> raw_surfaces;
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  for (const auto& [dim, tag] : groups) {
    if (dim != 2 && dim != 3) continue; // points and curves have no place in a TetMesh
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    if (name.empty()) name = "physical_" + std::to_string(tag);
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    if (dim == 3) {
      VolumeGroup group{name, tag, {}};
      for (const int entity : entities) {
        std::vector<std::size_t> tags;
        std::vector<std::size_t> nodes;
        gmsh::model::mesh::getElementsByType(k_gmsh_tetrahedron, tags, nodes, entity);
        for (const std::size_t t : tags) group.tets.push_back(tet_index_of(t));
      }
      std::sort(group.tets.begin(), group.tets.end());
      group.tets.erase(std::unique(group.tets.begin(), group.tets.end()), group.tets.end());
      mesh.volume_groups.push_back(std::move(group));
    } else {
      RawSurfaceGroup group{name, tag, {}};
      for (const int entity : entities) {
        std::vector<std::size_t> tags;
        std::vector<std::size_t> nodes;
        gmsh::model::mesh::getElementsByType(k_gmsh_triangle, tags, nodes, entity);
        for (std::size_t i = 0; i < tags.size(); ++i)
          group.triangles.push_back({tags[i], {nodes[3 * i], nodes[3 * i + 1], nodes[3 * i + 2]}});
      }
      std::sort(group.triangles.begin(), group.triangles.end());
      raw_surfaces.push_back(std::move(group));
    }
  }

  // Nodes: those used by tetrahedra or physical triangles, ascending tag.
  std::vector<std::size_t> node_tags;
  std::vector<double> coordinates;
  std::vector<double> parametric;
  gmsh::model::mesh::getNodes(node_tags, coordinates, parametric, -1, -1, /*includeBoundary=*/true,
                              /*returnParametricCoord=*/false);
  std::vector<std::size_t> used(tet_nodes.begin(), tet_nodes.end());
  for (const auto& group : raw_surfaces)
    for (const auto& triangle : group.triangles) used.insert(used.end(), triangle.second.begin(), triangle.second.end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  std::unordered_map<std::size_t, std::size_t> position; // node tag -> row in `coordinates`
  position.reserve(node_tags.size());
  for (std::size_t i = 0; i < node_tags.size(); ++i) position.emplace(node_tags[i], i);
  std::unordered_map<std::size_t, int> node_index; // node tag -> TetMesh row
  node_index.reserve(used.size());
  mesh.nodes.resize(static_cast<Eigen::Index>(used.size()), 3);
  for (std::size_t v = 0; v < used.size(); ++v) {
    const auto it = position.find(used[v]);
    if (it == position.end()) throw MeshError(file + ": element references missing node " + std::to_string(used[v]));
    for (int j = 0; j < 3; ++j)
      mesh.nodes(static_cast<Eigen::Index>(v), j) = coordinates[3 * it->second + static_cast<std::size_t>(j)];
    node_index.emplace(used[v], static_cast<int>(v));
  }

  mesh.tets.resize(static_cast<Eigen::Index>(tet_tags.size()), 4);
  for (std::size_t i = 0; i < order.size(); ++i) {
    const auto t = static_cast<Eigen::Index>(i);
    for (int j = 0; j < 4; ++j) mesh.tets(t, j) = node_index.at(tet_nodes[4 * order[i] + static_cast<std::size_t>(j)]);
    // Positive orientation det[b - a, c - a, d - a] > 0: swapping two nodes flips the sign.
    const double volume = signed_volume(mesh.nodes.row(mesh.tets(t, 0)).transpose(), mesh.nodes.row(mesh.tets(t, 1)).transpose(),
                                        mesh.nodes.row(mesh.tets(t, 2)).transpose(), mesh.nodes.row(mesh.tets(t, 3)).transpose());
    if (orientation == TetOrientation::make_positive && volume < 0.0) std::swap(mesh.tets(t, 2), mesh.tets(t, 3));
  }

  for (auto& raw : raw_surfaces) {
    SurfaceGroup group{raw.name, raw.tag, Eigen::MatrixXi(static_cast<Eigen::Index>(raw.triangles.size()), 3)};
    for (std::size_t f = 0; f < raw.triangles.size(); ++f)
      for (int j = 0; j < 3; ++j)
        group.triangles(static_cast<Eigen::Index>(f), j) = node_index.at(raw.triangles[f].second[static_cast<std::size_t>(j)]);
    mesh.surface_groups.push_back(std::move(group));
  }
  return mesh;
}

/// Names of the parameters the currently opened .geo declared (ONELAB "Parameters/NAME").
std::set<std::string> declared_parameters() {
  std::vector<std::string> names;
  gmsh::onelab::getNames(names);
  std::set<std::string> declared;
  for (const auto& name : names)
    if (name.rfind(k_parameter_prefix, 0) == 0) declared.insert(name.substr(k_parameter_prefix.size()));
  return declared;
}

std::string join(const std::set<std::string>& names) {
  std::string joined;
  for (const auto& name : names) joined += (joined.empty() ? "" : ", ") + name;
  return joined.empty() ? "(none)" : joined;
}

std::string number_text(double value) {
  std::ostringstream text;
  text.precision(17);
  text << value;
  return text.str();
}

} // namespace

TetMesh mesh_geo(const fs::path& geo, const std::map<std::string, double>& parameters, double element_size) {
  require_element_size(geo, element_size);
  require_file(geo, ".geo");
  GmshSession session(geo.string());
  const std::string file = fs::absolute(geo).string();
  if (parameters.empty()) {
    session.run("reading", [&] { gmsh::open(file); });
  } else {
    // Pass 1 opens the file with its defaults to learn which parameters it declares (the
    // DefineConstant blocks come first, so the names are known even if the defaults alone make
    // the geometry fail: such errors are left to pass 2). Pass 2 reopens it with the overrides
    // in the ONELAB database, which DefineConstant reads in preference to its default (a
    // parameter defaulted from another, e.g. cut_offset = length / 2, follows it). Verified
    // against gmsh 4.8.4 by test_geo_library.
    std::string defaults_error;
    try {
      session.run("reading", [&] { gmsh::open(file); });
    } catch (const MeshError& e) {
      defaults_error = e.what(); // reported by pass 2 if it persists with the overrides
    }
    const std::set<std::string> declared = declared_parameters();
    for (const auto& [name, value] : parameters) {
      if (declared.count(name) == 0 && !defaults_error.empty()) throw MeshError(defaults_error);
      if (declared.count(name) == 0)
        throw MeshError(geo.string() + ": unknown parameter '" + name + "'; the file declares: " + join(declared));
      if (!std::isfinite(value))
        throw MeshError(geo.string() + ": parameter '" + name + "' must be finite, got " + number_text(value));
    }
    GmshSession::reset();
    for (const auto& [name, value] : parameters)
      gmsh::onelab::setNumber(std::string(k_parameter_prefix) + name, {value});
    session.run("reading with parameters", [&] { gmsh::open(file); });
    for (const auto& [name, value] : parameters) {
      std::vector<double> used;
      gmsh::onelab::getNumber(std::string(k_parameter_prefix) + name, used);
      if (used.size() != 1 || used.front() != value)
        throw MeshError(geo.string() + ": parameter '" + name + "' = " + number_text(value) +
                        " was not applied (is it read-only in the .geo?)");
    }
  }
  session.run("meshing", [&] {
    set_volume_meshing_options(element_size);
    gmsh::model::mesh::generate(3);
  });
  return extract_tet_mesh(geo.string(), TetOrientation::make_positive);
}

std::set<std::string> geo_parameter_names(const fs::path& geo) {
  require_file(geo, ".geo");
  GmshSession session(geo.string());
  const std::string file = fs::absolute(geo).string();
  try {
    session.run("reading", [&] { gmsh::open(file); });
  } catch (const MeshError&) {
    // The DefineConstant blocks come first: their names are known even if the defaults alone make
    // the geometry fail (see mesh_geo).
  }
  return declared_parameters();
}

TetMesh mesh_stl(const fs::path& stl, double element_size, double scale) {
  require_element_size(stl, element_size);
  if (!(scale > 0.0) || !std::isfinite(scale))
    throw MeshError(stl.string() + ": scale must be positive, got " + number_text(scale));
  require_file(stl, "STL");
  GmshSession session(stl.string());
  session.run("reading", [&] { gmsh::merge(fs::absolute(stl).string()); });
  std::vector<int> surface_types;
  gmsh::model::mesh::getElementTypes(surface_types, 2);
  if (std::find(surface_types.begin(), surface_types.end(), k_gmsh_triangle) == surface_types.end())
    throw MeshError(stl.string() + ": holds no triangles");
  session.run("meshing", [&] {
    // Split the triangulation into patches at dihedral angles above 40 degrees and give each a
    // parametrisation, then close them into one volume (gmsh tutorial t13).
    gmsh::model::mesh::classifySurfaces(40.0 * std::numbers::pi / 180.0, /*boundary=*/true,
                                        /*forReparametrization=*/true, /*curveAngle=*/std::numbers::pi);
    gmsh::model::mesh::createGeometry();
    gmsh::vectorpair surfaces;
    gmsh::model::getEntities(surfaces, 2);
    std::vector<int> surface_tags;
    for (const auto& dim_tag : surfaces) surface_tags.push_back(dim_tag.second);
    const int loop = gmsh::model::geo::addSurfaceLoop(surface_tags);
    const int volume = gmsh::model::geo::addVolume({loop});
    gmsh::model::geo::synchronize();
    const int body = gmsh::model::addPhysicalGroup(3, {volume});
    gmsh::model::setPhysicalName(3, body, "body");
    const int boundary = gmsh::model::addPhysicalGroup(2, surface_tags);
    gmsh::model::setPhysicalName(2, boundary, "boundary");
    // The STL is meshed in its own units, then the nodes are scaled to metres.
    set_volume_meshing_options(element_size / scale);
    gmsh::model::mesh::generate(3);
  });
  TetMesh mesh = extract_tet_mesh(stl.string(), TetOrientation::make_positive);
  mesh.nodes *= scale;
  return mesh;
}

TetMesh read_msh(const fs::path& msh) {
  require_file(msh, ".msh");
  GmshSession session(msh.string());
  session.run("reading", [&] { gmsh::open(fs::absolute(msh).string()); });
  // A file is read as written: an inverted element stays inverted, so the quality check of
  // whoever loads it (scene_mesh) can refuse it instead of silently flipping a broken mesh.
  return extract_tet_mesh(msh.string(), TetOrientation::as_stored);
}

namespace {

void validate_for_writing(const TetMesh& mesh, const std::string& file) {
  const auto in_range = [&](int node) { return node >= 0 && node < mesh.nodes.rows(); };
  if (mesh.nodes.cols() != 3 || (mesh.tets.rows() > 0 && mesh.tets.cols() != 4))
    throw MeshError(file + ": mesh nodes must be #V by 3 and tets #T by 4");
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    for (int j = 0; j < 4; ++j)
      if (!in_range(mesh.tets(t, j)))
        throw MeshError(file + ": tetrahedron " + std::to_string(t) + " references missing node " + std::to_string(mesh.tets(t, j)));
  for (const auto& group : mesh.volume_groups)
    for (const int t : group.tets)
      if (t < 0 || t >= mesh.tets.rows())
        throw MeshError(file + ": volume group '" + group.name + "' references missing tetrahedron " + std::to_string(t));
  for (const auto& group : mesh.surface_groups) {
    if (group.triangles.rows() > 0 && group.triangles.cols() != 3)
      throw MeshError(file + ": surface group '" + group.name + "' triangles must be #F by 3");
    for (Eigen::Index f = 0; f < group.triangles.rows(); ++f)
      for (int j = 0; j < 3; ++j)
        if (!in_range(group.triangles(f, j)))
          throw MeshError(file + ": surface group '" + group.name + "' references missing node " + std::to_string(group.triangles(f, j)));
  }
}

/// Physical tags for groups of one dimension: the group's own tag when positive and unused, else
/// the next free one.
std::vector<int> physical_tags(const std::vector<int>& wanted) {
  std::set<int> used;
  std::vector<int> tags(wanted.size(), -1);
  for (std::size_t g = 0; g < wanted.size(); ++g)
    if (wanted[g] > 0 && used.insert(wanted[g]).second) tags[g] = wanted[g];
  int next = used.empty() ? 1 : *used.rbegin() + 1;
  for (auto& tag : tags)
    if (tag < 0) tag = next++;
  return tags;
}

} // namespace

void write_msh(const TetMesh& mesh, const fs::path& msh) {
  const std::string file = msh.string();
  validate_for_writing(mesh, file);
  GmshSession session(file);
  const auto node_tag = [](int node) { return static_cast<std::size_t>(node) + 1; };
  bool all_elements_grouped = mesh.tets.rows() > 0;

  session.run("building the model", [&] {
    gmsh::model::add("kerf");
    // Volume entities: one per distinct set of volume groups a tetrahedron belongs to, so that
    // each physical volume is a union of entities.
    std::vector<std::vector<int>> tet_membership(static_cast<std::size_t>(mesh.tets.rows()));
    for (std::size_t g = 0; g < mesh.volume_groups.size(); ++g)
      for (const int t : mesh.volume_groups[g].tets) tet_membership[static_cast<std::size_t>(t)].push_back(static_cast<int>(g));
    std::map<std::vector<int>, std::vector<int>> tets_by_membership;
    for (std::size_t t = 0; t < tet_membership.size(); ++t) {
      auto& membership = tet_membership[t];
      std::sort(membership.begin(), membership.end());
      membership.erase(std::unique(membership.begin(), membership.end()), membership.end());
      if (membership.empty()) all_elements_grouped = false;
      tets_by_membership[membership].push_back(static_cast<int>(t));
    }
    std::vector<std::pair<std::vector<int>, int>> volume_entities; // membership, entity tag
    const int node_entity = gmsh::model::addDiscreteEntity(3);
    volume_entities.push_back({{}, node_entity});
    std::vector<std::size_t> tags(static_cast<std::size_t>(mesh.nodes.rows()));
    std::iota(tags.begin(), tags.end(), std::size_t{1});
    std::vector<double> coordinates(3 * tags.size());
    for (Eigen::Index v = 0; v < mesh.nodes.rows(); ++v)
      for (int j = 0; j < 3; ++j) coordinates[static_cast<std::size_t>(3 * v + j)] = mesh.nodes(v, j);
    gmsh::model::mesh::addNodes(3, node_entity, tags, coordinates);
    bool node_entity_used = false;
    for (const auto& [membership, tets] : tets_by_membership) {
      const int entity = node_entity_used ? gmsh::model::addDiscreteEntity(3) : node_entity;
      if (node_entity_used) volume_entities.push_back({membership, entity});
      else volume_entities.front().first = membership;
      node_entity_used = true;
      std::vector<std::size_t> element_tags;
      std::vector<std::size_t> element_nodes;
      for (const int t : tets) {
        element_tags.push_back(static_cast<std::size_t>(t) + 1); // element tag = row + 1
        for (int j = 0; j < 4; ++j) element_nodes.push_back(node_tag(mesh.tets(t, j)));
      }
      gmsh::model::mesh::addElementsByType(entity, k_gmsh_tetrahedron, element_tags, element_nodes);
    }

    // Surface entities: triangles deduplicated by their node set, one entity per distinct set of
    // surface groups; element tags continue after the tetrahedra in order of first appearance.
    std::map<std::array<int, 3>, std::size_t> triangle_index;
    std::vector<std::array<int, 3>> triangles;
    std::vector<std::vector<int>> triangle_membership;
    for (std::size_t g = 0; g < mesh.surface_groups.size(); ++g) {
      const auto& F = mesh.surface_groups[g].triangles;
      for (Eigen::Index f = 0; f < F.rows(); ++f) {
        std::array<int, 3> key{F(f, 0), F(f, 1), F(f, 2)};
        std::sort(key.begin(), key.end());
        const auto [it, inserted] = triangle_index.emplace(key, triangles.size());
        if (inserted) {
          triangles.push_back({F(f, 0), F(f, 1), F(f, 2)});
          triangle_membership.emplace_back();
        }
        auto& membership = triangle_membership[it->second];
        if (membership.empty() || membership.back() != static_cast<int>(g)) membership.push_back(static_cast<int>(g));
      }
    }
    std::map<std::vector<int>, std::vector<std::size_t>> triangles_by_membership;
    for (std::size_t i = 0; i < triangles.size(); ++i) triangles_by_membership[triangle_membership[i]].push_back(i);
    std::vector<std::pair<std::vector<int>, int>> surface_entities;
    const auto first_triangle_tag = static_cast<std::size_t>(mesh.tets.rows()) + 1;
    for (const auto& [membership, members] : triangles_by_membership) {
      const int entity = gmsh::model::addDiscreteEntity(2);
      surface_entities.push_back({membership, entity});
      std::vector<std::size_t> element_tags;
      std::vector<std::size_t> element_nodes;
      for (const std::size_t i : members) {
        element_tags.push_back(first_triangle_tag + i);
        for (const int node : triangles[i]) element_nodes.push_back(node_tag(node));
      }
      gmsh::model::mesh::addElementsByType(entity, k_gmsh_triangle, element_tags, element_nodes);
    }

    // Physical groups: each is the union of the entities whose membership includes it.
    const auto add_groups = [](int dim, const auto& groups, const auto& entities) {
      std::vector<int> wanted;
      for (const auto& group : groups) wanted.push_back(group.tag);
      const std::vector<int> tags = physical_tags(wanted);
      for (std::size_t g = 0; g < groups.size(); ++g) {
        std::vector<int> members;
        for (const auto& [membership, entity] : entities)
          if (std::binary_search(membership.begin(), membership.end(), static_cast<int>(g))) members.push_back(entity);
        if (members.empty()) continue; // an empty group has nothing to write
        gmsh::model::addPhysicalGroup(dim, members, tags[g]);
        gmsh::model::setPhysicalName(dim, tags[g], groups[g].name);
      }
    };
    add_groups(3, mesh.volume_groups, volume_entities);
    add_groups(2, mesh.surface_groups, surface_entities);

    gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
    gmsh::option::setNumber("Mesh.Binary", 0);
    // SaveAll = 0 writes the elements of physical groups only; a tetrahedron outside every
    // volume group would be lost, so then everything is written.
    gmsh::option::setNumber("Mesh.SaveAll", all_elements_grouped ? 0 : 1);
    gmsh::option::setNumber("Mesh.SaveParametric", 0);
  });

  try {
    write_atomically(msh, [&](const fs::path& temporary) {
      session.run("writing", [&] { gmsh::write(temporary.string()); });
    });
  } catch (const MeshError&) {
    throw;
  } catch (const std::exception& e) {
    throw MeshError(file + ": writing failed: " + e.what());
  }
}

} // namespace kerf
