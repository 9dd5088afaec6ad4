#include "experiments/study/study_spec.hpp"

#include "experiments/run/model_catalogue.hpp"

#include <toml++/toml.h>

#include <limits>
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
  for (const auto& [k, v] : t) {
    bool known = false;
    for (std::string_view a : keys) known = known || k.str() == a;
    if (!known) {
      std::string expected;
      for (std::string_view a : keys) expected += (expected.empty() ? "" : ", ") + std::string(a);
      fail(file, v.source(), prefix + std::string(k.str()), "unknown key (expected one of: " + expected + ")");
    }
  }
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
  allow_only(file, doc, "", {"study", "reference", "calibration"});
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
    allow_only(file, *ref, "reference.", {"degree", "refinements", "samples"});
    if (auto d = (*ref)["degree"]) {
      const auto v = d.value<int64_t>();
      if (!v || (*v != 1 && *v != 2)) fail(file, d.node()->source(), "reference.degree", "expected 1 or 2");
      spec.reference.degree = static_cast<int>(*v);
    }
    if (auto r = (*ref)["refinements"]) {
      const toml::array* a = r.as_array();
      if (!a || a->empty()) fail(file, r.node()->source(), "reference.refinements", "expected an array of levels >= 0");
      spec.reference.refinements.clear();
      for (const toml::node& n : *a) {
        const auto v = n.value<int64_t>();
        if (!v || *v < 0 || *v > 4) fail(file, n.source(), "reference.refinements", "expected a level in 0..4");
        spec.reference.refinements.push_back(static_cast<int>(*v));
      }
    }
    if (auto s = (*ref)["samples"]) {
      const auto v = s.value<int64_t>();
      if (!v || *v < 2 || *v > std::numeric_limits<int>::max())
        fail(file, s.node()->source(), "reference.samples", "expected an integer in 2..2147483647");
      spec.reference.samples = static_cast<int>(*v);
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
