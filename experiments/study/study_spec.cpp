// Study files (TOML) to StudySpec (study_spec.hpp): one function per table over the TOML reading
// layer the scene reader uses (formats/scene/toml_reader.hpp), so every error reads
// "FILE:LINE:COLUMN: KEY: expected what, got what". The format: docs/studies.md, "Study file".

#include "experiments/study/study_spec.hpp"

#include "experiments/calibration/free_parameters.hpp"
#include "experiments/models/model_description.hpp"
#include "formats/scene/toml_reader.hpp"
#include "experiments/study/model_resolution.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string_view>
#include <system_error>

namespace kerf {

namespace {

using namespace toml_reader;
namespace fs = std::filesystem;

/// A count of samples is an int: its bound is the type's, not a smaller policy.
constexpr std::int64_t int_max = std::numeric_limits<int>::max();
const std::string samples_range = "an integer in 2.." + std::to_string(int_max);

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

/// The study's scenes by name (their files' stems), as other tables name them.
std::vector<std::string> scene_names(const StudySpec& spec) {
  std::vector<std::string> out;
  for (const fs::path& p : spec.scenes) out.push_back(p.stem().string());
  return out;
}

bool contains(const std::vector<std::string>& names, std::string_view name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

/// The position of key `k` of table `t` (whose value is `v`), or of its value when toml++ has none
/// for the key.
toml::source_region key_position(const toml::key& k, const toml::node& v, const TableRef& t) {
  return k.source().begin.line != 0 ? k.source() : where(v, t);
}

/// The string at `k` of `t`: one of `names` (the study's scenes or models), described as `what`.
std::string one_of_study(const TableRef& t, std::string_view k, const std::vector<std::string>& names,
                         std::string_view what) {
  const std::string expected = std::string(what) + " (" + joined(names) + ")";
  const toml::node* n = t.find(k);
  if (n == nullptr) missing(t, k, expected);
  const auto* s = n->as_string();
  if (s == nullptr || !contains(names, s->get())) wrong(*n, t, t.key(k), expected);
  return s->get();
}

// --- [study] ---------------------------------------------------------------------------------------

/// The scene file a study names `name`: NAME beside the study file (a .toml file), else
/// experiments/scenes/NAME.toml.
std::optional<fs::path> find_scene(const fs::path& study_file, const std::string& name) {
  const fs::path beside = study_file.parent_path() / name;
  const fs::path named = fs::path(KERF_SCENES_DIR) / (name + ".toml");
  std::error_code ec; // a name the file system cannot look up (too long) is no scene, not an exception
  if (fs::exists(beside, ec) && beside.extension() == ".toml") return beside;
  if (fs::exists(named, ec)) return named;
  return std::nullopt;
}

void read_header(const TableRef& t, StudySpec& spec) {
  allow_only(t, {"name", "description", "scenes", "models"});
  spec.name = required_string(t, "name");
  spec.description = optional_string(t, "description").value_or("");
  const auto scenes = required_strings(t, "scenes");
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const auto file = find_scene(spec.file, scenes[i].first);
    if (!file)
      fail(t.file, where(*scenes[i].second, t), t.key("scenes"),
           "no scene \"" + scenes[i].first + "\" beside the study or in " + KERF_SCENES_DIR);
    spec.scenes.push_back(*file);
  }
  const auto models = required_strings(t, "models");
  for (std::size_t i = 0; i < models.size(); ++i) {
    if (find_model(models[i].first) == nullptr) {
      std::vector<std::string> catalogue;
      for (const ModelDescription& m : model_catalogue()) catalogue.emplace_back(m.name);
      wrong(*models[i].second, t, item_key(t.key("models"), i), "a model of the catalogue (" + joined(catalogue) + ")");
    }
    spec.models.push_back(models[i].first);
  }
}

// --- [reference] -----------------------------------------------------------------------------------

/// Mesh levels: ascending, the last the finest.
std::vector<int> mesh_levels(const toml::node& n, const TableRef& t, const std::string& key) {
  return ascending_integers(n, t, key, minimum_study_mesh_level, 4,
                            "ascending mesh levels in " + std::to_string(minimum_study_mesh_level) +
                                "..4 (level k: the scene's element size times 2^-k; the last is the finest)");
}

/// An element degree: 1 or 2.
int element_degree(const toml::node& n, const TableRef& t, const std::string& key) {
  return integer_in(n, t, key, 1, 2, "1 or 2");
}

/// A number of reference samples: 2 or more.
int sample_count(const toml::node& n, const TableRef& t, const std::string& key) {
  return integer_in(n, t, key, 2, int_max, samples_range);
}

/// `KEY = { SCENE = VALUE, ... }` of [reference]: a scene of the study's own value, each read by
/// `read(node, table, key)`.
template <typename Value, typename Read>
std::map<std::string, Value> per_scene(const TableRef& t, std::string_view k, const StudySpec& spec,
                                       std::string_view value, Read read) {
  std::map<std::string, Value> out;
  const auto table = optional_table(t, k, "a table { SCENE = " + std::string(value) + " }");
  if (!table) return out;
  const std::vector<std::string> scenes = scene_names(spec);
  for (auto&& [name, node] : table->table) {
    const std::string scene(name.str());
    if (!contains(scenes, scene))
      fail(t.file, where(node, *table), table->key(scene), "expected a scene of study.scenes (" + joined(scenes) + ")");
    out[scene] = read(node, *table, table->key(scene));
  }
  return out;
}

/// [reference] library: a folder, relative to the study file (it need not exist yet).
fs::path library_folder(const TableRef& t, const fs::path& study_file) {
  const std::string name = *optional_string(t, "library");
  check(!name.empty(), t, "library", "a folder, relative to the study file");
  const fs::path folder = (study_file.parent_path() / name).lexically_normal();
  std::error_code ec;
  if (fs::exists(folder, ec) && !fs::is_directory(folder, ec))
    fail_at(t, "library", "expected a folder, not the file " + folder.string());
  return folder;
}

void read_reference(const TableRef& t, StudySpec& spec) {
  allow_only(t, {"degree", "scene_degree", "refinements", "scene_refinements", "samples", "scene_samples",
                 "adaptive", "time_verification", "linear_solver", "fracture", "library"});
  spec.has_reference = true;
  StudyReferenceSpec& r = spec.reference;
  // Unset: each scene's own degree ([geometry] element_degree).
  if (const toml::node* n = t.find("degree")) r.degree = element_degree(*n, t, t.key("degree"));
  r.scene_degree = per_scene<int>(t, "scene_degree", spec, "1 or 2", element_degree);
  if (const toml::node* n = t.find("refinements")) r.refinements = mesh_levels(*n, t, t.key("refinements"));
  r.scene_refinements = per_scene<std::vector<int>>(t, "scene_refinements", spec, "[levels]", mesh_levels);
  if (const toml::node* n = t.find("samples")) r.samples = sample_count(*n, t, t.key("samples"));
  r.scene_samples = per_scene<int>(t, "scene_samples", spec, samples_range, sample_count);
  if (const auto adaptive = optional_number(t, "adaptive")) {
    r.adaptive = *adaptive;
    check(*adaptive >= 0.0 && *adaptive < 1.0, t, "adaptive", "a fraction of the peak force in [0, 1) (0: off)");
  }
  r.time_verification = optional_boolean(t, "time_verification").value_or(r.time_verification);
  if (t.find("library") != nullptr) r.library = library_folder(t, spec.file);
  using reference::LinearSolverChoice;
  r.linear_solver = optional_choice<LinearSolverChoice>(t, "linear_solver",
                                                        {{"auto", LinearSolverChoice::automatic},
                                                         {"direct", LinearSolverChoice::direct},
                                                         {"iterative", LinearSolverChoice::iterative}})
                        .value_or(r.linear_solver);
  r.fracture = optional_choice<ReferenceFracture>(t, "fracture",
                                                  {{"off", ReferenceFracture::off},
                                                   {"auto", ReferenceFracture::automatic},
                                                   {"on", ReferenceFracture::on}})
                   .value_or(r.fracture);
}

// --- [models.NAME] ---------------------------------------------------------------------------------

/// [models.NAME] resolutions: ascending values of the model's knob (model_resolution.hpp).
std::vector<int> model_resolutions(const toml::node& n, const TableRef& t, const std::string& model) {
  std::pair<int, int> range;
  try {
    range = resolution_range(model);
  } catch (const std::invalid_argument& e) {
    fail(t.file, where(n, t), t.key("resolutions"), e.what());
  }
  const std::string expected =
      "ascending integers in " + std::to_string(range.first) + ".." + std::to_string(range.second);
  return ascending_integers(n, t, t.key("resolutions"), range.first, range.second, expected);
}

void read_model_tables(const TableRef& doc, StudySpec& spec) {
  const auto models = optional_table(doc, "models", "tables [models.NAME]");
  if (!models) return;
  for (auto&& [name, section] : models->table) {
    const std::string model(name.str());
    if (!contains(spec.models, model))
      fail(doc.file, key_position(name, section, *models), models->key(model),
           "expected a model of study.models (" + joined(spec.models) + ")");
    const TableRef t = *optional_table(*models, model, "a table [" + models->key(model) + "]");
    allow_only(t, {"resolutions"});
    if (const toml::node* r = t.find("resolutions")) spec.resolutions[model] = model_resolutions(*r, t, model);
  }
}

// --- [calibration] ---------------------------------------------------------------------------------

/// A parameter file of [calibration]: beside the study, with a [models.*] table.
fs::path parameter_file(const toml::node& n, const TableRef& t, const std::string& key, const fs::path& study_file) {
  const std::string name = string_item(n, t, key, "a parameter file, relative to the study file");
  const fs::path file = study_file.parent_path() / name;
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    fail(t.file, where(n, t), key, "no parameter file \"" + name + "\" beside the study");
  if (calibrated_models(file).empty()) fail(t.file, where(n, t), key, file.string() + " has no [models.*] table");
  return file;
}

void read_calibrations(const TableRef& doc, StudySpec& spec) {
  const auto calibration = optional_table(doc, "calibration", "a table [calibration] of SCENE = [parameter files]");
  if (!calibration) return;
  const std::vector<std::string> scenes = scene_names(spec);
  for (auto&& [name, files] : calibration->table) {
    const std::string scene(name.str());
    const std::string key = calibration->key(scene);
    if (!contains(scenes, scene))
      fail(doc.file, key_position(name, files, *calibration), key,
           "expected a scene of study.scenes (" + joined(scenes) + ")");
    const toml::array& a = non_empty_array(files, *calibration, key, "an array of parameter files");
    for (std::size_t i = 0; i < a.size(); ++i)
      spec.calibrations[scene].push_back(parameter_file(*a.get(i), *calibration, item_key(key, i), spec.file));
  }
}

// --- [[calibrate]] ---------------------------------------------------------------------------------

StudyCalibrationFit read_fit(const TableRef& t, const StudySpec& spec) {
  allow_only(t, {"scene", "model", "speed", "max_evaluations", "samples"});
  StudyCalibrationFit fit;
  fit.scene = one_of_study(t, "scene", scene_names(spec), "a scene of study.scenes");
  fit.model = one_of_study(t, "model", spec.models, "a model of study.models");
  if (free_parameters(fit.model).empty())
    fail_at(t, "model", "model \"" + fit.model + "\" has no free parameters to calibrate");
  if (const auto speed = optional_number(t, "speed")) {
    fit.speed = *speed;
    check(*speed > 0.0 && *speed != 1.0, t, "speed",
          "a speed factor > 0 other than 1 (the scene's own trajectory is held out)");
  }
  fit.max_evaluations =
      optional_integer_in(t, "max_evaluations", 1, 100000, "an integer in 1..100000").value_or(fit.max_evaluations);
  fit.samples = optional_integer_in(t, "samples", 2, 100000, "an integer in 2..100000").value_or(fit.samples);
  return fit;
}

/// One calibrated row per model and scene: a fit that no parameter file of [calibration] and no
/// other fit already gives.
void check_fit_is_new(const TableRef& t, const StudySpec& spec, const StudyCalibrationFit& fit) {
  const std::string what = "model " + fit.model + " on " + fit.scene;
  const auto files = spec.calibrations.find(fit.scene);
  if (files != spec.calibrations.end())
    for (const fs::path& f : files->second) {
      const auto models = calibrated_models(f);
      if (contains(models, fit.model))
        fail(t.file, t.where, t.path, what + " is already calibrated by " + f.string() +
                                          " ([calibration]): one calibrated row per model and scene");
    }
  for (const StudyCalibrationFit& other : spec.fits)
    if (other.scene == fit.scene && other.model == fit.model) fail(t.file, t.where, t.path, what + " is fitted twice");
}

void read_fits(const TableRef& doc, StudySpec& spec) {
  const toml::node* n = doc.find("calibrate");
  if (n == nullptr) return;
  const std::vector<TableRef> fits = table_array(doc, "calibrate", ElementPaths::array_name);
  if (fits.empty()) wrong(*n, doc, "calibrate", "tables [[calibrate]]");
  if (!spec.has_reference)
    fail(doc.file, where(*n, doc), "calibrate", "a fitted calibration needs the study's [reference] to fit to");
  for (const TableRef& t : fits) {
    const StudyCalibrationFit fit = read_fit(t, spec);
    check_fit_is_new(t, spec, fit);
    spec.fits.push_back(fit);
  }
}

} // namespace

StudySpec read_study(const std::filesystem::path& file) {
  try {
    // Study files report an unknown key at its value (StudySpec.ErrorsNameFileLineColumnAndKey).
    const SourceFile source{file.string(), UnknownKeyAt::value};
    const toml::table root = parse_file(file, source.name + ": cannot open the study file");
    const TableRef doc = TableRef::root(source, root);
    allow_only(doc, {"study", "reference", "calibration", "calibrate", "models"});
    StudySpec spec;
    spec.file = file;
    read_header(required_table(doc, "study"), spec);
    if (const auto reference = optional_table(doc, "reference")) read_reference(*reference, spec);
    read_model_tables(doc, spec);
    read_calibrations(doc, spec);
    read_fits(doc, spec);
    return spec;
  } catch (const TomlError& e) {
    throw StudyError(e.what());
  }
}

std::vector<std::string> calibrated_models(const std::filesystem::path& parameter_file) {
  toml::table doc;
  try {
    doc = parse_file(parameter_file, parameter_file.string() + ": cannot open the parameter file");
  } catch (const TomlError& e) {
    throw StudyError(e.what());
  }
  std::vector<std::string> out;
  if (const toml::table* models = doc["models"].as_table())
    for (const auto& [name, section] : *models) out.emplace_back(name.str());
  return out;
}

} // namespace kerf
