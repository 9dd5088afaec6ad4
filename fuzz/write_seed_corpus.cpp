// Writes the seed corpora of the fuzz targets from the repository's own files (real inputs are the
// best seeds), into the build tree, so nothing is duplicated in git:
//   seeds/scene/           the scene files given on the command line, copied
//   seeds/quantity/        every string value of those scenes, prefixed with the Dimension byte
//                          under which parse_quantity accepts it (0 when none does)
//   seeds/trajectory_csv/  each tool's trajectory of each readable scene as a recorded CSV
//   seeds/session_csv/     the same motion as a session file, written by SessionRecorder
//   seeds/profile_csv/     the same motion as a force profile, written by write_profile_csv
//   seeds/device_protocol/ the same motion as device-state datagrams, then a force command
//   seeds/reference_checkpoint/ the same motion as a reference checkpoint (kerf's own writer), and
//                          its first two samples alone (a small checkpoint)
//   seeds/replay/          the trajectory CSVs and session files above (both are replay files)
//   seeds/study/           the study files given with --study, copied, and each again with a
//                          [calibration] entry for its first scene naming calibrated.toml (the
//                          parameter file fuzz_study writes beside the input)
//   seeds/parameter_file/  the [models.*] tables of each scene in experiments/scenes, as a
//                          parameter file, after the byte that makes fuzz_parameter_file pick
//                          that scene (its index in the sorted folder)
//   seeds/study_table/     each Markdown table of the --results pages (docs/results.md, written
//                          by `kerf study`) as the study.csv it was written beside ("–" empty)
// The CSV seeds carry the scenes' sampled motion (at most 64 rows); forces are zero and modes
// cycle through the five spellings, so every column form is present (the seeds give the fuzzer
// the formats' structure, not physics).
//
//   write_seed_corpus OUT_DIR [--study STUDY.toml]... [--results PAGE.md]... SCENE.toml...

#include "formats/profile/force_profile.hpp"
#include "experiments/reference_run/reference_checkpoint.hpp"
#include "formats/scene/quantity.hpp"
#include "formats/scene/scene_reader.hpp"
#include "realtime/haptics/device_protocol.hpp"
#include "realtime/haptics/session_recorder.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace kerf;

namespace {

constexpr std::array modes{InteractionMode::no_contact, InteractionMode::deformation_1, InteractionMode::rupture,
                           InteractionMode::cutting, InteractionMode::deformation_2};

void write_bytes(const fs::path& file, const std::vector<std::byte>& bytes) {
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error(file.string() + ": cannot write the seed");
}

/// Every string value in a TOML tree.
void collect_strings(const toml::node& node, std::vector<std::string>& out) {
  if (const auto* s = node.as_string()) out.push_back(s->get());
  else if (const auto* t = node.as_table())
    for (const auto& [key, value] : *t) collect_strings(value, out);
  else if (const auto* a = node.as_array())
    for (const auto& value : *a) collect_strings(value, out);
}

void write_quantity_seeds(const fs::path& scene_file, const fs::path& out, std::set<std::string>& written) {
  toml::table doc;
  try {
    doc = toml::parse_file(scene_file.string());
  } catch (const toml::parse_error&) {
    return; // a deliberately malformed scene: it seeds the scene target only
  }
  std::vector<std::string> strings;
  collect_strings(doc, strings);
  for (const std::string& s : strings) {
    if (!written.insert(s).second) continue; // one seed per distinct text
    std::uint8_t dimension = 0;
    for (int d = 0; d <= static_cast<int>(Dimension::stiffness_per_area); ++d) {
      try {
        parse_quantity(s, static_cast<Dimension>(d));
        dimension = static_cast<std::uint8_t>(d);
        break;
      } catch (const QuantityError&) {
      }
    }
    std::vector<std::byte> bytes{static_cast<std::byte>(dimension)};
    for (char c : s) bytes.push_back(static_cast<std::byte>(c));
    write_bytes(out / ("q" + std::to_string(written.size())), bytes);
  }
}

/// A reference checkpoint of `tool`'s rows of `profile` (at most `max_samples` of them) as solved
/// samples, with the manifest record of each (reference_run.cpp's fields; the energy record as
/// EnergyBookkeeping::to_json writes it) and its positions as the solver state.
ReferenceCheckpoint reference_checkpoint_seed(const ForceProfile& profile, const std::string& tool,
                                              std::size_t stride, std::size_t max_samples) {
  ReferenceCheckpoint checkpoint;
  checkpoint.scene_sha256 = std::string(64, '0');
  checkpoint.degree = 1;
  checkpoint.processes = 1;
  for (const ProfileRow& row : profile.rows) {
    if (row.tool != tool) continue;
    if (checkpoint.indices.size() == max_samples) break;
    const std::size_t k = checkpoint.indices.size();
    checkpoint.indices.push_back(k * stride);
    checkpoint.profile.rows.push_back(row);
    for (int d = 0; d < 3; ++d) checkpoint.state.push_back(row.position[d]);
    const nlohmann::json p = {row.position.x(), row.position.y(), row.position.z()};
    const nlohmann::json f = {row.force.x(), row.force.y(), row.force.z()};
    checkpoint.samples.push_back({{"index", k * stride}, {"t_s", row.t}, {"newton_iterations", 3}, {"cutbacks", 0},
                                  {"increments", 1}, {"residual_N", 1e-9}, {"seconds", 0.01}, {"tool_force_N", f},
                                  {"support_reaction_N", f}, {"contact_points", static_cast<int>(k % 2)},
                                  {"energy", {{"external_work_J", 0.0}, {"stored_elastic_energy_J", 0.0},
                                              {"interface_energy_J", 0.0}, {"cohesive_dissipation_J", 0.0},
                                              {"viscous_dissipation_J", 0.0}, {"friction_dissipation_J", 0.0},
                                              {"failed_area_m2", 0.0}, {"balance_error", 0.0},
                                              {"last_positions_m", nlohmann::json::array({p})},
                                              {"last_forces_on_body_N", nlohmann::json::array({f})}}}});
    checkpoint.solve_seconds += 0.01;
  }
  checkpoint.solved = checkpoint.indices.size();
  if (!checkpoint.profile.rows.empty()) checkpoint.last.tool_position = checkpoint.profile.rows.back().position;
  checkpoint.last.load_factor = 1.0;
  return checkpoint;
}

void write_motion_seeds(const Scene& scene, const fs::path& out) {
  const std::string name = scene.file.stem().string();
  std::vector<SampledTrajectory> motion;
  for (const Tool& tool : scene.tools) motion.push_back(sample(tool.trajectory));
  const std::size_t samples = motion.front().samples.size();
  const std::size_t stride = std::max<std::size_t>(1, samples / 64);

  // Recorded trajectory CSV, one per tool: t,px,py,pz (also a replay file).
  for (std::size_t i = 0; i < motion.size(); ++i) {
    const fs::path file = out / "trajectory_csv" / (name + "_" + scene.tools[i].name + ".csv");
    std::ofstream csv(file);
    csv << "t,px,py,pz\n";
    char row[128];
    for (std::size_t k = 0; k < motion[i].samples.size(); k += stride) {
      const ToolState& s = motion[i].samples[k];
      std::snprintf(row, sizeof row, "%.17g,%.17g,%.17g,%.17g\n", s.time, s.position.x(), s.position.y(),
                    s.position.z());
      csv << row;
    }
    csv.close();
    fs::copy_file(file, out / "replay" / file.filename(), fs::copy_options::overwrite_existing);
  }

  // Session file and force profile: every tool at each kept sample.
  SessionHeader header{1000.0, "seed", name, {}};
  for (const Tool& tool : scene.tools) header.tools.push_back(tool.name);
  ForceProfile profile;
  {
    SessionRecorder recorder(out / "session_csv" / (name + ".csv"), header, samples + 2);
    std::uint64_t tick = 0;
    for (std::size_t k = 0; k < samples; k += stride, ++tick) {
      TickRecord r;
      r.tick = tick;
      r.t = motion.front().samples[k].time;
      r.tools = static_cast<int>(motion.size());
      for (std::size_t i = 0; i < motion.size(); ++i) {
        const ToolState& s = motion[i].samples[std::min(k, motion[i].samples.size() - 1)];
        r.tool[i].position = s.position;
        r.tool[i].velocity = s.velocity;
        r.tool[i].mode = modes[tick % modes.size()];
        ProfileRow row;
        row.t = s.time;
        row.tool = scene.tools[i].name;
        row.position = s.position;
        row.mode = modes[tick % modes.size()];
        profile.rows.push_back(row);
      }
      recorder.push(r);
    }
    recorder.close();
  }
  fs::copy_file(out / "session_csv" / (name + ".csv"), out / "replay" / (name + "_session.csv"),
                fs::copy_options::overwrite_existing);
  write_profile_csv(profile, out / "profile_csv" / (name + ".csv"));

  // Reference checkpoints: every kept sample of the first tool, and its first two samples only
  // (a small seed: the fuzzer's mutations of it stay small, and so does the kept corpus).
  write_reference_checkpoint(reference_checkpoint_seed(profile, scene.tools.front().name, stride, profile.rows.size()),
                             out / "reference_checkpoint" / (name + ".bin"));
  write_reference_checkpoint(reference_checkpoint_seed(profile, scene.tools.front().name, stride, 2),
                             out / "reference_checkpoint" / (name + "_small.bin"));

  // Device protocol: length-prefixed datagrams (fuzz_targets.hpp), the first tool's motion.
  std::vector<std::byte> stream;
  std::uint32_t sequence = 0;
  for (std::size_t k = 0; k < samples; k += stride) {
    DeviceStatePacket p;
    p.sequence = ++sequence;
    p.timestamp_ns = 1000000ull * sequence;
    p.position = motion.front().samples[k].position;
    p.max_force = 8.5;
    std::array<std::byte, device_state_packet_size> bytes{};
    encode(p, bytes);
    stream.push_back(static_cast<std::byte>(bytes.size()));
    stream.insert(stream.end(), bytes.begin(), bytes.end());
  }
  ForceCommandPacket command;
  command.sequence = 1;
  command.echo_sequence = sequence;
  command.force = {0.0, 0.0, 1.0};
  std::array<std::byte, force_command_packet_size> bytes{};
  encode(command, bytes);
  stream.push_back(static_cast<std::byte>(bytes.size()));
  stream.insert(stream.end(), bytes.begin(), bytes.end());
  write_bytes(out / "device_protocol" / (name + ".bin"), stream);
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error(file.string() + ": cannot write the seed");
}

/// The study file, and the same with a [calibration] entry naming calibrated.toml for its first
/// scene (when it has none and its scenes parse).
void write_study_seeds(const fs::path& study, const fs::path& out) {
  const std::string text = read_text(study);
  write_text(out / study.filename(), text);
  toml::table doc;
  try {
    doc = toml::parse(text, study.string());
  } catch (const toml::parse_error&) {
    return;
  }
  const auto first_scene = doc["study"]["scenes"][0].value<std::string>();
  if (!first_scene || doc.contains("calibration")) return;
  write_text(out / (study.stem().string() + "_calibrated.toml"),
             text + "\n[calibration]\n" + *first_scene + " = [\"calibrated.toml\"]\n");
}

/// One seed per scene of experiments/scenes with [models.*] tables: the byte that picks it in
/// fuzz_parameter_file (its index in the sorted folder), then those tables as a parameter file.
int write_parameter_file_seeds(const fs::path& out) {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::directory_iterator(KERF_SCENES_DIR))
    if (e.path().extension() == ".toml") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  int written = 0;
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const toml::table doc = toml::parse_file(scenes[k].string());
    const toml::table* models = doc["models"].as_table();
    if (models == nullptr) continue;
    std::ostringstream text;
    text << "# the [models.*] tables of " << scenes[k].filename().string() << "\n"
         << toml::table{{"models", *models}} << "\n";
    std::vector<std::byte> bytes{static_cast<std::byte>(k)};
    for (char c : text.str()) bytes.push_back(static_cast<std::byte>(c));
    write_bytes(out / (scenes[k].stem().string() + ".toml"), bytes);
    ++written;
  }
  return written;
}

/// Splits a Markdown table row "| a | b |" into its cells, trimmed.
std::vector<std::string> markdown_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  for (std::size_t k = 1; k < line.size(); ++k) {
    if (line[k] != '|') {
      cell += line[k];
      continue;
    }
    const auto first = cell.find_first_not_of(' ');
    const auto last = cell.find_last_not_of(' ');
    cells.push_back(first == std::string::npos ? "" : cell.substr(first, last - first + 1));
    cell.clear();
  }
  return cells;
}

/// Each Markdown table of `page` as a CSV (RFC 4180; "–", not measured, as an empty field).
int write_study_table_seeds(const fs::path& page, const fs::path& out) {
  std::istringstream lines(read_text(page));
  std::string csv;
  int tables = 0;
  const auto flush = [&] {
    if (csv.empty()) return;
    write_text(out / (page.stem().string() + "_" + std::to_string(++tables) + ".csv"), csv);
    csv.clear();
  };
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("|", 0) != 0) {
      flush();
      continue;
    }
    if (line.rfind("|---", 0) == 0) continue; // the alignment row
    std::string row;
    for (const std::string& cell : markdown_cells(line)) {
      std::string field = cell == "–" ? "" : cell;
      if (field.find_first_of(",\"") != std::string::npos) {
        std::string quoted = "\"";
        for (char c : field) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
        field = quoted + "\"";
      }
      row += (row.empty() ? "" : ",") + field;
    }
    csv += row + "\n";
  }
  flush();
  return tables;
}

} // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: write_seed_corpus OUT_DIR [--study STUDY.toml]... [--results PAGE.md]... SCENE.toml...\n";
    return 64;
  }
  const fs::path out = argv[1];
  for (const char* target : {"scene", "quantity", "trajectory_csv", "session_csv", "profile_csv", "device_protocol",
                             "study", "parameter_file", "study_table", "reference_checkpoint", "replay"})
    fs::create_directories(out / target);
  std::set<std::string> quantities;
  int scenes = 0, readable = 0, studies = 0, tables = 0, parameter_files = 0;
  try {
    parameter_files = write_parameter_file_seeds(out / "parameter_file");
    for (int a = 2; a < argc; ++a) {
      const std::string option = argv[a];
      if ((option == "--study" || option == "--results") && a + 1 < argc) {
        const fs::path file = argv[++a];
        if (option == "--study") {
          write_study_seeds(file, out / "study");
          ++studies;
        } else {
          tables += write_study_table_seeds(file, out / "study_table");
        }
        continue;
      }
      const fs::path file = argv[a];
      fs::copy_file(file, out / "scene" / (file.parent_path().filename().string() + "_" + file.filename().string()),
                    fs::copy_options::overwrite_existing);
      ++scenes;
      write_quantity_seeds(file, out / "quantity", quantities);
      Scene scene;
      try {
        scene = read_scene(file);
      } catch (const SceneError&) {
        continue; // the bad scenes of tests/experiments/scene seed the scene target only
      }
      write_motion_seeds(scene, out);
      ++readable;
    }
  } catch (const std::exception& e) {
    std::cerr << "write_seed_corpus: " << e.what() << '\n';
    return 1;
  }
  std::cout << "write_seed_corpus: " << scenes << " scene files (" << readable << " readable), " << quantities.size()
            << " quantities, " << studies << " studies, " << parameter_files << " parameter files, " << tables
            << " study tables -> " << out.string() << '\n';
  return 0;
}
