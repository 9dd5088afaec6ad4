#include "experiments/study/study_spec.hpp"

#include "experiments/calibration/free_parameters.hpp"
#include "experiments/models/model_description.hpp"
#include "experiments/study/model_resolution.hpp"
#include "experiments/scene/toml_keys.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <limits>
#include <map>
#include <string_view>
#include <system_error>

namespace kerf {

namespace {

[[noreturn]] void fail(const std::filesystem::path& file, const toml::source_region& where, const std::string& key,
                       const std::string& what) {
  throw StudyError(file.string() + ":" + std::to_string(where.begin.line) + ":" + std::to_string(where.begin.column) +
                   ": " + key + ": " + what);
}

void allow_only(const std::filesystem::path& file, const toml::table& t, const std::string& prefix,
                std::initializer_list<std::string_view> keys) {
  const toml::node* value = nullptr;
  if (const toml::key* k = first_unknown_key(t, keys, &value))
    fail(file, value->source(), prefix + std::string(k->str()), "unknown key (expected one of: " + allowed_keys_text(keys) + ")");
}

std::vector<std::string> strings(const std::filesystem::path& file, const toml::table& t, const std::string& key,
                                 const std::string& prefix) {
  const toml::array* a = t[key].as_array();
  if (!a) fail(file, t.source(), prefix + key, "expected an array of strings");
  std::vector<std::string> out;
  for (const toml::node& n : *a) {
    const auto s = n.value<std::string>();
    if (!s || s->empty()) fail(file, n.source(), prefix + key, "expected a non-empty string");
    out.push_back(*s);
  }
  if (out.empty()) fail(file, a->source(), prefix + key, "expected at least one entry");
  return out;
}

} // namespace

StudySpec read_study(const std::filesystem::path& file) {
  toml::table doc;
  try {
    doc = toml::parse_file(file.string());
  } catch (const toml::parse_error& e) {
    throw StudyError(file.string() + ":" + std::to_string(e.source().begin.line) + ":" +
                     std::to_string(e.source().begin.column) + ": TOML syntax: " + std::string(e.description()));
  }
  StudySpec spec;
  spec.file = file;
  allow_only(file, doc, "", {"study", "reference", "calibration", "calibrate", "models"});
  const toml::table* study = doc["study"].as_table();
  if (!study) throw StudyError(file.string() + ": missing table [study]");
  allow_only(file, *study, "study.", {"name", "description", "scenes", "models"});
  const auto name = (*study)["name"].value<std::string>();
  if (!name || name->empty()) fail(file, study->source(), "study.name", "expected a non-empty string");
  spec.name = *name;
  spec.description = (*study)["description"].value_or(std::string{});
  for (const std::string& s : strings(file, *study, "scenes", "study.")) {
    const std::filesystem::path beside = file.parent_path() / s;
    const std::filesystem::path named = std::filesystem::path(KERF_SCENES_DIR) / (s + ".toml");
    std::error_code ec; // a name the file system cannot look up (too long) is no scene, not an exception
    if (std::filesystem::exists(beside, ec) && beside.extension() == ".toml") spec.scenes.push_back(beside);
    else if (std::filesystem::exists(named, ec)) spec.scenes.push_back(named);
    else fail(file, (*study)["scenes"].node()->source(), "study.scenes", "no scene \"" + s + "\" beside the study or in " + KERF_SCENES_DIR);
  }
  for (const std::string& m : strings(file, *study, "models", "study.")) {
    if (!find_model(m)) fail(file, (*study)["models"].node()->source(), "study.models", "unknown model \"" + m + "\"");
    spec.models.push_back(m);
  }
  if (const toml::table* ref = doc["reference"].as_table()) {
    spec.has_reference = true;
    allow_only(file, *ref, "reference.", {"degree", "scene_degree", "refinements", "scene_refinements", "samples", "scene_samples", "linear_solver",
                                           "fracture", "library"});
    if (auto d = (*ref)["degree"]) {
      // Integers are TOML integers, as in scene files: value_exact, never toml++'s value<int64_t>(),
      // which casts a float (6.7e87, say) to int64_t unchecked (undefined behaviour; found by
      // fuzz_study, fuzz/regressions/study/).
      const auto v = d.value_exact<int64_t>();
      if (!v || (*v != 1 && *v != 2)) fail(file, d.node()->source(), "reference.degree", "expected 1 or 2");
      spec.reference.degree = static_cast<int>(*v); // else each scene's own
    }
    // An array of ascending mesh levels, the last the finest.
    auto read_levels = [&](const toml::node_view<const toml::node>& r, const std::string& key) {
      const toml::array* a = r.as_array();
      const std::string range = std::to_string(minimum_study_mesh_level) + "..4";
      if (!a || a->empty()) fail(file, r.node()->source(), key, "expected an array of levels in " + range);
      std::vector<int> levels;
      for (const toml::node& n : *a) {
        const auto v = n.value_exact<int64_t>();
        if (!v || *v < minimum_study_mesh_level || *v > 4)
          fail(file, n.source(), key, "expected a level in " + range + " (k < 0: the scene's element size times 2^-k)");
        if (!levels.empty() && *v <= levels.back()) fail(file, n.source(), key, "expected ascending levels (the last is the finest)");
        levels.push_back(static_cast<int>(*v));
      }
      return levels;
    };
    if (auto r = (*ref)["refinements"]) spec.reference.refinements = read_levels(r, "reference.refinements");
    if (auto r = (*ref)["scene_refinements"]) {
      const toml::table* t = r.as_table();
      if (!t) fail(file, r.node()->source(), "reference.scene_refinements", "expected a table { SCENE = [levels] }");
      for (const auto& [name, levels] : *t) {
        const std::string scene(name.str());
        const bool known = std::any_of(spec.scenes.begin(), spec.scenes.end(),
                                       [&](const std::filesystem::path& p) { return p.stem().string() == scene; });
        if (!known) fail(file, levels.source(), "reference.scene_refinements." + scene, "expected a scene of study.scenes");
        spec.reference.scene_refinements[scene] =
            read_levels(toml::node_view<const toml::node>(&levels), "reference.scene_refinements." + scene);
      }
    }
    // A table { SCENE = integer } of the study's scenes, each value in [lo, hi].
    auto read_scene_integers = [&](std::string_view table_key, std::int64_t lo, std::int64_t hi, const std::string& expected) {
      std::map<std::string, int> values;
      const std::string path = "reference." + std::string(table_key);
      const auto r = (*ref)[table_key];
      const toml::table* t = r.as_table();
      if (!t) fail(file, r.node()->source(), path, "expected a table { SCENE = " + expected + " }");
      for (const auto& [name, value] : *t) {
        const std::string scene(name.str());
        const std::string key = path + "." + scene;
        const bool known = std::any_of(spec.scenes.begin(), spec.scenes.end(),
                                       [&](const std::filesystem::path& p) { return p.stem().string() == scene; });
        if (!known) fail(file, value.source(), key, "expected a scene of study.scenes");
        const auto v = value.value_exact<int64_t>();
        if (!v || *v < lo || *v > hi) fail(file, value.source(), key, "expected " + expected);
        values[scene] = static_cast<int>(*v);
      }
      return values;
    };
    if ((*ref)["scene_degree"]) spec.reference.scene_degree = read_scene_integers("scene_degree", 1, 2, "1 or 2");
    if (auto l = (*ref)["library"]) {
      const auto v = l.value<std::string>();
      if (!v || v->empty()) fail(file, l.node()->source(), "reference.library", "expected a folder, relative to the study file");
      spec.reference.library = (file.parent_path() / *v).lexically_normal();
      if (std::filesystem::exists(spec.reference.library) && !std::filesystem::is_directory(spec.reference.library))
        fail(file, l.node()->source(), "reference.library", "expected a folder, not the file " + spec.reference.library.string());
    }
    if (auto s = (*ref)["samples"]) {
      const auto v = s.value_exact<int64_t>();
      if (!v || *v < 2 || *v > std::numeric_limits<int>::max())
        fail(file, s.node()->source(), "reference.samples", "expected an integer in 2..2147483647");
      spec.reference.samples = static_cast<int>(*v);
    }
    if ((*ref)["scene_samples"])
      spec.reference.scene_samples =
          read_scene_integers("scene_samples", 2, std::numeric_limits<int>::max(), "an integer in 2..2147483647");
    if (auto s = (*ref)["linear_solver"]) {
      const auto v = s.value<std::string>();
      if (v == "auto") spec.reference.linear_solver = reference::LinearSolverChoice::automatic;
      else if (v == "direct") spec.reference.linear_solver = reference::LinearSolverChoice::direct;
      else if (v == "iterative") spec.reference.linear_solver = reference::LinearSolverChoice::iterative;
      else fail(file, s.node()->source(), "reference.linear_solver", "expected \"auto\", \"direct\" or \"iterative\"");
    }
    if (auto s = (*ref)["fracture"]) {
      const auto v = s.value<std::string>();
      if (v == "off") spec.reference.fracture = ReferenceFracture::off;
      else if (v == "auto") spec.reference.fracture = ReferenceFracture::automatic;
      else if (v == "on") spec.reference.fracture = ReferenceFracture::on;
      else fail(file, s.node()->source(), "reference.fracture", "expected \"off\", \"auto\" or \"on\"");
    }
  }
  if (const toml::node* m = doc.get("models")) {
    const toml::table* models = m->as_table();
    if (!models) fail(file, m->source(), "models", "expected tables [models.NAME]");
    for (const auto& [name, section] : *models) {
      const std::string key = "models." + std::string(name.str());
      if (std::find(spec.models.begin(), spec.models.end(), name.str()) == spec.models.end())
        fail(file, name.source(), key, "expected a model of study.models");
      const toml::table* t = section.as_table();
      if (!t) fail(file, section.source(), key, "expected a table");
      allow_only(file, *t, key + ".", {"resolutions"});
      const toml::node* r = t->get("resolutions");
      if (!r) continue;
      std::pair<int, int> range;
      try {
        range = resolution_range(std::string(name.str()));
      } catch (const std::invalid_argument& e) {
        fail(file, r->source(), key + ".resolutions", e.what());
      }
      const std::string expected = "expected ascending integers in " + std::to_string(range.first) + ".." + std::to_string(range.second);
      const toml::array* a = r->as_array();
      if (!a || a->empty()) fail(file, r->source(), key + ".resolutions", expected);
      std::vector<int>& values = spec.resolutions[std::string(name.str())];
      for (const toml::node& n : *a) {
        const auto v = n.value_exact<int64_t>();
        if (!v || *v < range.first || *v > range.second || (!values.empty() && *v <= values.back()))
          fail(file, n.source(), key + ".resolutions", expected);
        values.push_back(static_cast<int>(*v));
      }
    }
  }
  if (const toml::node* c = doc.get("calibration")) {
    const toml::table* cal = c->as_table();
    if (!cal) fail(file, c->source(), "calibration", "expected a table [calibration] of scene = [parameter files]");
    for (const auto& [scene, files] : *cal) {
      const std::string key = "calibration." + std::string(scene.str());
      bool known = false;
      for (const std::filesystem::path& f : spec.scenes) known = known || f.stem() == scene.str();
      if (!known) fail(file, scene.source(), key, "no scene of that name in study.scenes");
      const toml::array* a = files.as_array();
      if (!a || a->empty()) fail(file, files.source(), key, "expected an array of parameter files");
      for (const toml::node& n : *a) {
        const auto name = n.value<std::string>();
        const std::filesystem::path p = file.parent_path() / name.value_or("");
        std::error_code ec;
        if (!name || !std::filesystem::is_regular_file(p, ec)) fail(file, n.source(), key, "no parameter file \"" + name.value_or("") + "\" beside the study");
        if (calibrated_models(p).empty()) fail(file, n.source(), key, p.string() + " has no [models.*] table");
        spec.calibrations[std::string(scene.str())].push_back(p);
      }
    }
  }
  if (const toml::node* c = doc.get("calibrate")) {
    const toml::array* fits = c->as_array();
    if (!fits || !fits->is_array_of_tables()) fail(file, c->source(), "calibrate", "expected tables [[calibrate]]");
    if (!spec.has_reference) fail(file, c->source(), "calibrate", "a fitted calibration needs the study's [reference] to fit to");
    for (const toml::node& n : *fits) {
      const toml::table& t = *n.as_table();
      allow_only(file, t, "calibrate.", {"scene", "model", "speed", "max_evaluations", "samples"});
      StudyCalibrationFit fit;
      const auto scene = t["scene"].value<std::string>();
      bool known = false;
      for (const std::filesystem::path& f : spec.scenes) known = known || (scene && f.stem() == *scene);
      if (!known) fail(file, t["scene"].node() ? t["scene"].node()->source() : t.source(), "calibrate.scene", "expected a scene of study.scenes");
      fit.scene = *scene;
      const auto model = t["model"].value<std::string>();
      if (!model || std::find(spec.models.begin(), spec.models.end(), *model) == spec.models.end())
        fail(file, t["model"].node() ? t["model"].node()->source() : t.source(), "calibrate.model", "expected a model of study.models");
      if (free_parameters(*model).empty())
        fail(file, t["model"].node()->source(), "calibrate.model", "model \"" + *model + "\" has no free parameters to calibrate");
      fit.model = *model;
      if (auto v = t["speed"]) {
        const auto f = v.value<double>();
        if (!f || !(*f > 0.0) || *f == 1.0)
          fail(file, v.node()->source(), "calibrate.speed", "expected a speed factor > 0 other than 1 (the scene's own trajectory is held out)");
        fit.speed = *f;
      }
      if (auto v = t["max_evaluations"]) {
        const auto e = v.value_exact<int64_t>();
        if (!e || *e < 1 || *e > 100000) fail(file, v.node()->source(), "calibrate.max_evaluations", "expected an integer in 1..100000");
        fit.max_evaluations = static_cast<int>(*e);
      }
      if (auto v = t["samples"]) {
        const auto n = v.value_exact<int64_t>();
        if (!n || *n < 2 || *n > 100000) fail(file, v.node()->source(), "calibrate.samples", "expected an integer in 2..100000");
        fit.samples = static_cast<int>(*n);
      }
      const auto files = spec.calibrations.find(fit.scene);
      if (files != spec.calibrations.end())
        for (const std::filesystem::path& f : files->second) {
          const auto models = calibrated_models(f);
          if (std::find(models.begin(), models.end(), fit.model) != models.end())
            fail(file, t.source(), "calibrate", "model " + fit.model + " on " + fit.scene + " is already calibrated by " + f.string() +
                                                    " ([calibration]): one calibrated row per model and scene");
        }
      for (const StudyCalibrationFit& other : spec.fits)
        if (other.scene == fit.scene && other.model == fit.model)
          fail(file, t.source(), "calibrate", "model " + fit.model + " on " + fit.scene + " is fitted twice");
      spec.fits.push_back(fit);
    }
  }
  return spec;
}

std::vector<std::string> calibrated_models(const std::filesystem::path& parameter_file) {
  toml::table doc;
  try {
    doc = toml::parse_file(parameter_file.string());
  } catch (const toml::parse_error& e) {
    throw StudyError(parameter_file.string() + ":" + std::to_string(e.source().begin.line) + ":" +
                     std::to_string(e.source().begin.column) + ": TOML syntax: " + std::string(e.description()));
  }
  std::vector<std::string> out;
  if (const toml::table* models = doc["models"].as_table())
    for (const auto& [name, section] : *models) out.emplace_back(name.str());
  return out;
}

} // namespace kerf
