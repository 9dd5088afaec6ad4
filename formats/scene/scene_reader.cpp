// Scene files (TOML, toml++) to Scene (scene_reader.hpp), one function per table over the TOML
// reading layer (toml_reader.hpp): every key is known, every quantity is converted once, and every
// error reads "FILE:LINE:COLUMN: KEY: expected what, got what". The format: docs/scenes.md.

#include "formats/scene/scene_reader.hpp"

#include "formats/scene/quantity.hpp"
#include "formats/scene/toml_reader.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <initializer_list>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace kerf {

namespace fs = std::filesystem;

std::vector<fs::path> geometry_search_path() {
  std::vector<fs::path> dirs;
#ifdef KERF_GEO_DIR
  dirs.emplace_back(KERF_GEO_DIR);
#endif
  if (const char* env = std::getenv("KERF_GEO_PATH")) {
    std::string_view rest(env);
    while (!rest.empty()) {
      const std::size_t colon = rest.find(':');
      const std::string_view dir = rest.substr(0, colon);
      if (!dir.empty()) dirs.emplace_back(std::string(dir));
      if (colon == std::string_view::npos) break;
      rest.remove_prefix(colon + 1);
    }
  }
  return dirs;
}

namespace {

using namespace toml_reader;

/// Whether `word` occurs in `text` as a whole identifier.
bool mentions_identifier(std::string_view text, std::string_view word) {
  const auto is_ident = [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  };
  for (std::size_t pos = text.find(word); pos != std::string_view::npos; pos = text.find(word, pos + 1)) {
    const bool left = pos == 0 || !is_ident(text[pos - 1]);
    const bool right = pos + word.size() == text.size() || !is_ident(text[pos + word.size()]);
    if (left && right) return true;
  }
  return false;
}

constexpr double pi = std::numbers::pi;

/// Reads one scene file; every error names file:line:column and the key path.
class SceneParser {
public:
  SceneParser(const fs::path& file, std::vector<fs::path> extra_includes)
      : m_file(file), m_source{file.string()}, m_folder(fs::absolute(file).lexically_normal().parent_path()),
        m_extra_includes(std::move(extra_includes)) {}

  Scene read() {
    toml::table root = parse_file(m_file, m_source.name + ": cannot open the scene file");
    const TableRef doc = TableRef::root(m_source, root);
    allow_only(doc, {"scene", "geometry", "material", "layers", "supports", "tools", "models", "include"});
    include_parameter_files(doc, root);

    Scene scene;
    scene.file = m_file;
    read_header(required_table(doc, "scene"), scene);
    scene.geometry = read_geometry(required_table(doc, "geometry"));
    scene.material = read_material(required_table(doc, "material"), nullptr, scene.phenomena);
    read_layers(doc, scene);
    read_supports(doc, scene);
    read_tools(doc, scene);
    if (const auto models = optional_table(doc, "models")) {
      allow_only(*models, {"fracture", "voxel", "springs"});
      if (const auto t = optional_table(*models, "fracture")) scene.fracture = read_fracture(*t);
      if (const auto t = optional_table(*models, "voxel")) scene.voxel = read_voxel(*t);
      if (const auto t = optional_table(*models, "springs")) scene.springs = read_springs(*t);
    }
    check_consistency(scene);
    return scene;
  }

private:
  fs::path m_file;
  SourceFile m_source; ///< the file as messages name it
  fs::path m_folder;
  std::vector<fs::path> m_extra_includes; ///< parameter files given by the caller, after the scene's own
  /// The [scene].phenomena entries, for consistency errors at the right place.
  struct PhenomenonEntry {
    Phenomenon phenomenon;
    const toml::node* node;
    std::string key; ///< "scene.phenomena[k]"
  };
  std::vector<PhenomenonEntry> m_phenomenon_nodes;
  const toml::node* m_phenomena_node = nullptr;
  std::vector<toml::source_region> m_tool_where;
  std::vector<toml::source_region> m_layer_where;
  /// The text of a .geo geometry ("" for stl/msh): parameters and physical names are checked in it.
  std::string m_geo_text;
  std::string m_geo_name;

  /// A .geo must define the physical group `name` (a support surface or a layer volume); stl and
  /// msh files are not checked here.
  void check_physical_name(const TableRef& t, std::string_view key, const std::string& name,
                           std::string_view what) const {
    if (m_geo_text.empty()) return;
    if (m_geo_text.find("\"" + name + "\"") != std::string::npos) return;
    fail_at(t, key, "expected " + std::string(what) + " defined in " + m_geo_name + ", got \"" + name +
             "\" (no such physical group)");
  }

  // --- files ----------------------------------------------------------------------------------

  /// Resolves `name` against the scene's folder, then `search`; fails at `key` if not found.
  fs::path resolve_file(const TableRef& t, std::string_view key, const std::string& name,
                        const std::vector<fs::path>& search) const {
    const fs::path p(name);
    std::vector<fs::path> candidates;
    if (p.is_absolute()) {
      candidates.push_back(p);
    } else {
      candidates.push_back(m_folder / p);
      for (const fs::path& dir : search) candidates.push_back(dir / p);
    }
    std::error_code ec;
    for (const fs::path& c : candidates)
      if (fs::is_regular_file(c, ec)) return fs::absolute(c).lexically_normal();
    std::string looked;
    for (const fs::path& c : candidates) {
      if (!looked.empty()) looked += ", ";
      looked += c.lexically_normal().string();
    }
    fail_at(t, key, "file \"" + name + "\" not found (looked for: " + looked + ")");
  }

  // --- included parameter files ---------------------------------------------------------------

  /// `include = "FILE.toml"` or `include = ["A.toml", "B.toml"]` (resolved against the scene's
  /// folder), then the caller's extra files: each parameter file holds [models.*] tables only —
  /// calibrated model parameters (`kerf calibrate`) — and its keys replace the scene's keys of
  /// the same table, in order. Geometry, material, supports and tools stay in the scene itself,
  /// so an include never changes what the reference solves (nor its cache key). Its values are
  /// read, unit-converted and checked below as if written in the scene; errors name the
  /// parameter file's line.
  void include_parameter_files(const TableRef& doc, toml::table& root) const {
    std::vector<fs::path> files;
    if (const toml::node* n = doc.find("include")) {
      const std::string expected = "a parameter file name or an array of them";
      std::vector<const toml::node*> names;
      if (const toml::array* a = n->as_array()) {
        for (const toml::node& e : *a) names.push_back(&e);
      } else {
        names.push_back(n);
      }
      for (const toml::node* e : names) {
        const auto* s = e->as_string();
        if (s == nullptr || s->get().empty()) wrong(*e, doc, "include", expected);
        files.push_back(resolve_file(doc, "include", s->get(), {}));
      }
    }
    for (const fs::path& f : m_extra_includes) files.push_back(f);
    for (const fs::path& file : files) merge_parameter_file(root, file);
    root.erase("include");
  }

  void merge_parameter_file(toml::table& root, const fs::path& file) const {
    toml::table included =
        parse_file(file, m_source.name + ": include: cannot open the parameter file " + file.string());
    for (auto&& [key, value] : included) {
      if (key.str() != "models" || !value.is_table())
        fail(m_source, key.source().begin.line != 0 ? key.source() : value.source(), key.str(),
             "a parameter file holds [models.*] tables only (calibrated model parameters; geometry, material, "
             "supports and tools stay in the scene)");
      if (!root.contains("models")) root.insert("models", toml::table{});
      toml::table* models = root["models"].as_table();
      if (models == nullptr) return; // the scene's own "models" is not a table: reported where it is read
      for (auto&& [model, section] : *value.as_table()) {
        const std::string path = "models." + std::string(model.str());
        if (!section.is_table()) fail(m_source, section.source(), path, "expected a table [" + path + "]");
        if (!models->contains(model.str())) models->insert(model.str(), toml::table{});
        toml::table* into = (*models)[model.str()].as_table();
        if (into == nullptr) continue; // reported where the scene's value is read
        // Moved, not copied: toml++ keeps a node's source position only when it is moved.
        for (auto&& [k, v] : *section.as_table()) into->insert_or_assign(k.str(), std::move(v));
      }
    }
  }

  // --- sections -------------------------------------------------------------------------------

  void read_header(const TableRef& t, Scene& scene) {
    allow_only(t, {"name", "description", "phenomena"});
    scene.name = required_string(t, "name");
    scene.description = optional_string(t, "description").value_or("");
    const toml::node* n = t.find("phenomena");
    const std::string expected = "a non-empty array of phenomena (deformation, cutting, tearing, friction, layers)";
    if (n == nullptr) missing(t, "phenomena", expected);
    const toml::array& a = non_empty_array(*n, t, t.key("phenomena"), expected);
    m_phenomena_node = n;
    for (std::size_t k = 0; k < a.size(); ++k) {
      const toml::node& e = *a.get(k);
      const std::string path = item_key(t.key("phenomena"), k);
      const auto* s = e.as_string();
      const std::optional<Phenomenon> p = s ? phenomenon_from_string(s->get()) : std::nullopt;
      if (!p) wrong(e, t, path, "one of deformation, cutting, tearing, friction, layers");
      if (scene.phenomena.contains(*p)) fail(m_source, where(e, t), path, "\"" + s->get() + "\" is listed twice");
      scene.phenomena.insert(*p);
      m_phenomenon_nodes.push_back({*p, &e, path});
    }
  }

  SceneGeometry read_geometry(const TableRef& t) {
    allow_only(t, {"geo", "stl", "msh", "stl_scale", "element_size", "element_degree", "parameters"});
    SceneGeometry g;
    read_geometry_source(t, g);
    if (t.find("stl_scale") != nullptr) {
      if (g.kind != SceneGeometry::Kind::stl)
        fail_at(t, "stl_scale", "only applies to stl geometry");
      g.stl_scale = required_quantity(t, "stl_scale", Dimension::dimensionless);
      check(g.stl_scale > 0.0, t, "stl_scale", "a scale > 0");
    }
    if (g.kind == SceneGeometry::Kind::msh) {
      g.element_size = optional_quantity(t, "element_size", Dimension::length).value_or(0.0);
      if (t.find("element_size") != nullptr) check(g.element_size > 0.0, t, "element_size", "a length > 0");
    } else {
      g.element_size = required_quantity(t, "element_size", Dimension::length);
      check(g.element_size > 0.0, t, "element_size", "a length > 0");
    }
    g.nominal_element_size = g.element_size;
    if (const auto degree = optional_integer_in(t, "element_degree", 1, 2, "1 (linear tetrahedra) or 2 (quadratic)"))
      g.element_degree = *degree;
    if (t.find("parameters") != nullptr) {
      if (g.kind != SceneGeometry::Kind::geo)
        fail_at(t, "parameters", "only applies to geo geometry");
      read_geo_parameters(*optional_table(t, "parameters"), g);
    }
    return g;
  }

  /// Exactly one of geo, stl, msh: the geometry's file, found beside the scene or on the geometry
  /// search path (a .geo file's text kept to check names against).
  void read_geometry_source(const TableRef& t, SceneGeometry& g) {
    std::string_view source_key;
    for (std::string_view k : {"geo", "stl", "msh"}) {
      if (t.find(k) == nullptr) continue;
      if (!source_key.empty())
        fail_at(t, k,
                "give exactly one of geo, stl, msh (found " + std::string(source_key) + " and " + std::string(k) + ")");
      source_key = k;
    }
    if (source_key.empty()) missing(t, "geo", "one of geo = \"NAME.geo\", stl = \"NAME.stl\", msh = \"NAME.msh\"");
    g.kind = source_key == "geo" ? SceneGeometry::Kind::geo
             : source_key == "stl" ? SceneGeometry::Kind::stl
                                   : SceneGeometry::Kind::msh;
    const std::string name = required_string(t, source_key);
    const std::string extension = "." + std::string(source_key);
    if (fs::path(name).extension() != extension)
      wrong(*t.find(source_key), t, t.key(source_key), "a file name ending in " + extension);
    g.source = resolve_file(t, source_key, name, geometry_search_path());
    if (g.kind == SceneGeometry::Kind::geo) {
      std::ifstream in(g.source, std::ios::binary);
      std::ostringstream s;
      s << in.rdbuf();
      m_geo_text = s.str();
      m_geo_name = g.source.filename().string();
    }
  }

  /// [geometry.parameters]: values of the .geo file's parameters, each one the file names.
  void read_geo_parameters(const TableRef& p, SceneGeometry& g) const {
    for (auto&& [k, v] : p.table) {
      const std::string key = p.key(k.str());
      // Catch misspelt parameters: a .geo parameter is named in its file.
      if (!mentions_identifier(m_geo_text, k.str()))
        fail(m_source, k.source().begin.line != 0 ? k.source() : where(v, p), key,
             "unknown parameter (" + g.source.filename().string() + " does not define \"" + std::string(k.str()) +
                 "\")");
      // Strings carry a length unit; plain numbers are SI or unitless (cut_normal).
      g.parameters[std::string(k.str())] = quantity(v, p, key, Dimension::length);
    }
  }

  /// The base material (`base == nullptr`, region "body") or a layer: a copy of `base` with the
  /// keys the layer gives.
  Material read_material(const TableRef& t, const Material* base, PhenomenonSet phenomena) const {
    const bool layer = base != nullptr;
    if (layer)
      allow_only(t, {"region", "law", "youngs_modulus", "poisson_ratio", "density", "fracture_toughness",
                     "cohesive_strength", "friction_coefficient", "damping"});
    else
      allow_only(t, {"law", "youngs_modulus", "poisson_ratio", "density", "fracture_toughness",
                     "cohesive_strength", "friction_coefficient", "damping"});
    Material m = layer ? *base : Material{};
    m.region = layer ? required_string(t, "region") : "body";

    const std::initializer_list<std::pair<std::string_view, MaterialLaw>> laws{
        {"neo-hookean", MaterialLaw::neo_hookean},
        {"decoupled-neo-hookean", MaterialLaw::decoupled_neo_hookean},
        {"st-venant-kirchhoff", MaterialLaw::st_venant_kirchhoff}};
    if (const auto law = layer ? optional_choice(t, "law", laws) : std::optional(required_choice(t, "law", laws)))
      m.law = *law;

    // Required in the base material; cutting/tearing need J_c and σ_c, friction needs μ.
    const bool fracture = phenomena.contains(Phenomenon::cutting) || phenomena.contains(Phenomenon::tearing);
    const bool friction = phenomena.contains(Phenomenon::friction);
    const auto get = [&](std::string_view key, Dimension d, bool required, double& into) -> bool {
      const auto v = (required && !layer) ? std::optional(required_quantity(t, key, d)) : optional_quantity(t, key, d);
      if (v) into = *v;
      return v.has_value();
    };
    if (get("youngs_modulus", Dimension::pressure, true, m.youngs_modulus))
      check(m.youngs_modulus > 0.0, t, "youngs_modulus", "a modulus > 0");
    if (get("poisson_ratio", Dimension::dimensionless, true, m.poisson_ratio))
      check(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5, t, "poisson_ratio", "a ratio in (-1, 0.5)");
    if (get("density", Dimension::density, true, m.density))
      check(m.density > 0.0, t, "density", "a density > 0");
    if (get("fracture_toughness", Dimension::energy_per_area, fracture, m.fracture_toughness))
      check(m.fracture_toughness > 0.0, t, "fracture_toughness", "a toughness > 0");
    if (get("cohesive_strength", Dimension::pressure, fracture, m.cohesive_strength))
      check(m.cohesive_strength > 0.0, t, "cohesive_strength", "a strength > 0");
    if (get("friction_coefficient", Dimension::dimensionless, friction, m.friction_coefficient))
      check(m.friction_coefficient >= 0.0, t, "friction_coefficient", "a coefficient >= 0");
    if (get("damping", Dimension::viscosity, false, m.damping))
      check(m.damping >= 0.0, t, "damping", "a viscosity >= 0");
    return m;
  }

  void read_layers(const TableRef& doc, Scene& scene) {
    std::set<std::string> regions;
    for (const TableRef& t : table_array(doc, "layers")) {
      Material m = read_material(t, &scene.material, scene.phenomena);
      check_physical_name(t, "region", m.region, "a physical volume");
      if (!regions.insert(m.region).second || m.region == "body")
        fail_at(t, "region", "region \"" + m.region + "\" is already used (each layer needs its own physical volume)");
      scene.layers.push_back(std::move(m));
      m_layer_where.push_back(t.where);
    }
  }

  void read_supports(const TableRef& doc, Scene& scene) const {
    const auto tables = table_array(doc, "supports");
    if (tables.empty()) missing(doc, "supports", "at least one [[supports]] table with surface and kind");
    for (const TableRef& t : tables) {
      allow_only(t, {"surface", "kind"});
      Support s;
      s.surface = required_string(t, "surface");
      check_physical_name(t, "surface", s.surface, "a physical surface");
      s.kind = required_choice<Support::Kind>(t, "kind", {{"bonded", Support::Kind::bonded},
                                                         {"sliding", Support::Kind::sliding}});
      scene.supports.push_back(std::move(s));
    }
  }

  void read_tools(const TableRef& doc, Scene& scene) {
    const auto tables = table_array(doc, "tools");
    if (tables.empty()) missing(doc, "tools", "one or two [[tools]] tables");
    if (tables.size() > 2)
      fail(m_source, tables[2].where, tables[2].path,
           "a scene has one or two tools (found " + std::to_string(tables.size()) + ")");
    for (const TableRef& t : tables) {
      Tool tool;
      tool.name = required_string(t, "name");
      for (const Tool& other : scene.tools)
        if (other.name == tool.name)
          fail_at(t, "name", "tool name \"" + tool.name + "\" is used twice");
      tool.kind =
          required_choice<Tool::Kind>(t, "kind", {{"blade", Tool::Kind::blade}, {"sphere", Tool::Kind::sphere}});
      if (tool.kind == Tool::Kind::blade)
        tool.blade = read_blade(t);
      else
        read_sphere(t, tool);
      tool.trajectory = read_trajectory(required_table(t, "trajectory"));
      scene.tools.push_back(std::move(tool));
      m_tool_where.push_back(t.where);
    }
  }

  BladeShape read_blade(const TableRef& t) const {
    allow_only(t, {"name", "kind", "edge_direction", "cutting_direction", "edge_length", "wedge_angle",
                   "thickness", "trajectory"},
               "a blade tool");
    BladeShape b;
    b.edge_direction = vector3(t, "edge_direction", Dimension::dimensionless, true).normalized();
    b.cutting_direction = vector3(t, "cutting_direction", Dimension::dimensionless, true).normalized();
    if (!(std::abs(b.edge_direction.dot(b.cutting_direction)) < 1e-6)) {
      std::ostringstream cosine;
      cosine << b.edge_direction.dot(b.cutting_direction);
      fail_at(t, "cutting_direction",
              "expected a direction orthogonal to edge_direction, got " + found(*t.find("cutting_direction")) +
                  " (cosine " + cosine.str() + " with edge_direction " + found(*t.find("edge_direction")) + ")");
    }
    b.edge_length = required_quantity(t, "edge_length", Dimension::length);
    check(b.edge_length > 0.0, t, "edge_length", "a length > 0");
    b.wedge_angle = required_quantity(t, "wedge_angle", Dimension::angle);
    check(b.wedge_angle > 0.0 && b.wedge_angle < pi, t, "wedge_angle", "an angle in (0, 180 deg)");
    b.thickness = required_quantity(t, "thickness", Dimension::length);
    check(b.thickness > 0.0, t, "thickness", "a length > 0");
    return b;
  }

  void read_sphere(const TableRef& t, Tool& tool) const {
    allow_only(t, {"name", "kind", "radius", "grasp_radius", "grasp_stiffness", "trajectory"}, "a sphere tool");
    tool.radius = required_quantity(t, "radius", Dimension::length);
    check(tool.radius > 0.0, t, "radius", "a length > 0");
    if ((tool.grasp_radius = optional_quantity(t, "grasp_radius", Dimension::length)))
      check(*tool.grasp_radius > 0.0, t, "grasp_radius", "a length > 0");
    if ((tool.grasp_stiffness = optional_quantity(t, "grasp_stiffness", Dimension::stiffness_per_area))) {
      check(*tool.grasp_stiffness > 0.0, t, "grasp_stiffness", "a stiffness per area > 0");
      check(tool.grasp_radius.has_value(), t, "grasp_stiffness",
            "a grasp_radius beside it (the stiffness is the grasped disc's)");
    }
  }

  TrajectorySpec read_trajectory(const TableRef& t) const {
    allow_only(t, {"rate", "start", "segments", "file"});
    TrajectorySpec spec;
    spec.rate = required_quantity(t, "rate", Dimension::frequency);
    check(spec.rate > 0.0, t, "rate", "a frequency > 0");
    if (t.find("file") != nullptr) {
      for (std::string_view k : {"start", "segments"})
        if (t.find(k) != nullptr)
          fail_at(t, k, "a recorded trajectory (file) takes no start or segments");
      spec.recorded_file = resolve_file(t, "file", required_string(t, "file"), {});
      return spec;
    }
    spec.start = vector3(t, "start", Dimension::length, false);
    const auto segments = table_array(t, "segments");
    if (segments.empty()) missing(t, "segments", "at least one [[" + t.key("segments") + "]] (or file = \"NAME.csv\")");
    for (const TableRef& s : segments) {
      TrajectorySegment seg;
      seg.kind = required_choice<TrajectorySegment::Kind>(
          s, "kind", {{"move", TrajectorySegment::Kind::move}, {"dwell", TrajectorySegment::Kind::dwell}});
      if (seg.kind == TrajectorySegment::Kind::move) {
        allow_only(s, {"kind", "label", "to", "speed"}, "a move segment");
        seg.target = vector3(s, "to", Dimension::length, false);
        seg.speed = required_quantity(s, "speed", Dimension::velocity);
        check(seg.speed > 0.0, s, "speed", "a speed > 0");
      } else {
        allow_only(s, {"kind", "label", "duration"}, "a dwell segment");
        seg.duration = required_quantity(s, "duration", Dimension::time);
        check(seg.duration > 0.0, s, "duration", "a duration > 0");
      }
      seg.label = optional_string(s, "label").value_or("");
      spec.segments.push_back(std::move(seg));
    }
    return spec;
  }

  FractureResponseParameters read_fracture(const TableRef& t) const {
    allow_only(t, {"rupture_force_per_length", "rupture_deflection", "deformation_1_exponent", "crack_deflection",
                   "deformation_2_exponent", "lateral_stiffness", "presliding_stiffness", "presliding_stick_ratio"});
    FractureResponseParameters f;
    f.rupture_force_per_length = required_quantity(t, "rupture_force_per_length", Dimension::force_per_length);
    check(f.rupture_force_per_length > 0.0, t, "rupture_force_per_length", "a force per length > 0");
    f.rupture_deflection = required_quantity(t, "rupture_deflection", Dimension::length);
    check(f.rupture_deflection > 0.0, t, "rupture_deflection", "a length > 0");
    const std::string_view exponent = "an exponent 1, 2 or 3 (paper 001 §6)";
    f.deformation_1_exponent = required_integer_in(t, "deformation_1_exponent", 1, 3, exponent);
    f.crack_deflection = required_quantity(t, "crack_deflection", Dimension::length);
    check(f.crack_deflection > 0.0, t, "crack_deflection", "a length > 0");
    f.deformation_2_exponent = required_integer_in(t, "deformation_2_exponent", 1, 3, exponent);
    f.lateral_stiffness = required_quantity(t, "lateral_stiffness", Dimension::force_per_length);
    check(f.lateral_stiffness >= 0.0, t, "lateral_stiffness", "a stiffness >= 0");
    f.presliding_stiffness = required_quantity(t, "presliding_stiffness", Dimension::force_per_length);
    check(f.presliding_stiffness > 0.0, t, "presliding_stiffness", "a stiffness > 0");
    if (const auto r = optional_quantity(t, "presliding_stick_ratio", Dimension::dimensionless)) {
      f.presliding_stick_ratio = *r;
      check(*r >= 0.0 && *r < 1.0, t, "presliding_stick_ratio", "a ratio in [0, 1)");
    }
    return f;
  }

  VoxelModelSettings read_voxel(const TableRef& t) const {
    allow_only(t, {"elastic_coefficient", "friction_coefficient", "damping_coefficient", "critical_force_cutting",
                   "critical_force_depth", "advance_length", "grid", "depth_cutting_stiffness", "clip_friction"});
    VoxelModelSettings v;
    v.elastic_coefficient = required_quantity(t, "elastic_coefficient", Dimension::pressure);
    check(v.elastic_coefficient > 0.0, t, "elastic_coefficient", "a coefficient > 0");
    v.friction_coefficient = required_quantity(t, "friction_coefficient", Dimension::dimensionless);
    check(v.friction_coefficient >= 0.0, t, "friction_coefficient", "a coefficient >= 0");
    v.damping_coefficient = required_quantity(t, "damping_coefficient", Dimension::viscosity);
    check(v.damping_coefficient >= 0.0, t, "damping_coefficient", "a coefficient >= 0");
    v.critical_force_cutting = required_quantity(t, "critical_force_cutting", Dimension::force);
    check(v.critical_force_cutting > 0.0, t, "critical_force_cutting", "a force > 0");
    v.critical_force_depth = required_quantity(t, "critical_force_depth", Dimension::force);
    check(v.critical_force_depth > 0.0, t, "critical_force_depth", "a force > 0");
    v.advance_length = required_quantity(t, "advance_length", Dimension::length);
    check(v.advance_length > 0.0, t, "advance_length", "a length > 0");
    if (const toml::node* n = t.find("grid")) {
      const toml::array* a = n->as_array();
      const std::string expected = "an array of three cell counts >= 1, e.g. [10, 20, 20]";
      if (a == nullptr || a->size() != 3) wrong(*n, t, t.key("grid"), expected);
      for (std::size_t k = 0; k < 3; ++k) {
        const auto* i = a->get(k)->as_integer();
        if (i == nullptr || i->get() < 1 || i->get() > 100000) wrong(*n, t, t.key("grid"), expected);
        v.grid[k] = static_cast<int>(i->get());
      }
    }
    v.depth_cutting_stiffness = optional_boolean(t, "depth_cutting_stiffness").value_or(v.depth_cutting_stiffness);
    v.clip_friction = optional_boolean(t, "clip_friction").value_or(v.clip_friction);
    return v;
  }

  SpringsModelSettings read_springs(const TableRef& t) const {
    allow_only(t, {"stiffness_scale", "cells", "cell_size", "integrator", "volume_term", "tensile_limit", "damping",
                   "grasp_radius"});
    SpringsModelSettings s;
    if (const auto v = optional_quantity(t, "stiffness_scale", Dimension::dimensionless)) {
      s.stiffness_scale = *v;
      check(*v > 0.0, t, "stiffness_scale", "a factor > 0");
    }
    s.cells = optional_integer_in(t, "cells", 1, 64, "a cell count per side in 1 .. 64");
    if (const toml::node* n = t.find("cell_size")) {
      const auto* text = n->as_string();
      if (text == nullptr || text->get() != "auto") {
        s.cell_size = required_quantity(t, "cell_size", Dimension::length);
        check(*s.cell_size > 0.0, t, "cell_size", "a length > 0 or \"auto\"");
      }
    }
    s.integrator =
        optional_one_of(t, "integrator", {"explicit", "explicit-double", "implicit", "linear-implicit", "static"});
    s.volume_term = optional_boolean(t, "volume_term");
    if ((s.tensile_limit = optional_quantity(t, "tensile_limit", Dimension::pressure)))
      check(*s.tensile_limit > 0.0, t, "tensile_limit", "a stress > 0");
    if ((s.damping = optional_quantity(t, "damping", Dimension::viscosity)))
      check(*s.damping >= 0.0, t, "damping", "a viscosity >= 0");
    if ((s.grasp_radius = optional_quantity(t, "grasp_radius", Dimension::length)))
      check(*s.grasp_radius > 0.0, t, "grasp_radius", "a length > 0");
    return s;
  }

  // --- the scene as a whole ---------------------------------------------------------------------

  /// Fails at the entry of scene.phenomena that declares `p`.
  [[noreturn]] void fail_at_phenomenon(Phenomenon p, std::string_view message) const {
    for (const PhenomenonEntry& e : m_phenomenon_nodes)
      if (e.phenomenon == p) fail(m_source, e.node->source(), e.key, message);
    fail(m_source, m_phenomena_node->source(), "scene.phenomena", message);
  }

  void check_consistency(const Scene& scene) const {
    const bool has_layers = scene.phenomena.contains(Phenomenon::layers);
    if (!scene.layers.empty() && !has_layers)
      fail(m_source, m_layer_where.front(), "layers[0]",
           "the scene has [[layers]] but scene.phenomena does not declare \"layers\"");
    if (has_layers && scene.layers.empty())
      fail_at_phenomenon(Phenomenon::layers, "\"layers\" is declared but the scene has no [[layers]] table");
    if (scene.phenomena.contains(Phenomenon::cutting)) {
      bool blade = false;
      for (const Tool& tool : scene.tools) blade = blade || tool.kind == Tool::Kind::blade;
      // Paper 002 cuts with the tip of a cutting stick (a sphere tool) in its voxel model.
      if (!blade && !scene.voxel)
        fail_at_phenomenon(Phenomenon::cutting, "\"cutting\" needs a blade tool (found only sphere tools; a sphere cuts only with [models.voxel])");
    }
    if (scene.phenomena.contains(Phenomenon::tearing) && scene.tools.size() < 2)
      fail_at_phenomenon(Phenomenon::tearing, "\"tearing\" needs two tools pulling the body apart (found " + std::to_string(scene.tools.size()) + ")");
  }
};

} // namespace

const char* material_law_name(MaterialLaw law) {
  switch (law) {
  case MaterialLaw::neo_hookean: return "neo-hookean";
  case MaterialLaw::decoupled_neo_hookean: return "decoupled-neo-hookean";
  case MaterialLaw::st_venant_kirchhoff: return "st-venant-kirchhoff";
  }
  return "?";
}

Scene read_scene(const fs::path& file, const std::vector<fs::path>& parameter_files) {
  try {
    return SceneParser(file, parameter_files).read();
  } catch (const TomlError& e) {
    throw SceneError(e.what());
  }
}

} // namespace kerf
