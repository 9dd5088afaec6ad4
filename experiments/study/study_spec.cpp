#include "experiments/study/study_spec.hpp"

#include "experiments/run/model_catalogue.hpp"

#include <toml++/toml.h>

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
  allow_only(file, doc, "", {"study", "reference"});
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
    if (std::filesystem::exists(beside) && beside.extension() == ".toml") spec.scenes.push_back(beside);
    else if (std::filesystem::exists(named)) spec.scenes.push_back(named);
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
      if (!v || *v < 2) fail(file, s.node()->source(), "reference.samples", "expected an integer >= 2");
      spec.reference.samples = static_cast<int>(*v);
    }
  }
  return spec;
}

} // namespace kerf
