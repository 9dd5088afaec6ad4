// Writes the seed corpora of the fuzz targets from the repository's own files (issue 10: "seed
// corpora from the real files in the repo"), into the build tree, so nothing is duplicated in git:
//   seeds/scene/           the scene files given on the command line, copied
//   seeds/quantity/        every string value of those scenes, prefixed with the Dimension byte
//                          under which parse_quantity accepts it (0 when none does)
//   seeds/trajectory_csv/  each tool's trajectory of each readable scene as a recorded CSV
//   seeds/session_csv/     the same motion as a session file, written by SessionRecorder
//   seeds/profile_csv/     the same motion as a force profile, written by write_profile_csv
//   seeds/device_protocol/ the same motion as device-state datagrams, then a force command
// The CSV seeds carry the scenes' sampled motion (at most 64 rows); forces are zero and modes
// cycle through the five spellings, so every column form is present (the seeds give the fuzzer
// the formats' structure, not physics).
//
//   write_seed_corpus OUT_DIR SCENE.toml...

#include "experiments/profile/force_profile.hpp"
#include "experiments/scene/quantity.hpp"
#include "experiments/scene/scene_reader.hpp"
#include "realtime/haptics/device_protocol.hpp"
#include "realtime/haptics/session_recorder.hpp"

#include <toml++/toml.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <set>
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
    for (int d = 0; d <= static_cast<int>(Dimension::viscosity); ++d) {
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

void write_motion_seeds(const Scene& scene, const fs::path& out) {
  const std::string name = scene.file.stem().string();
  std::vector<SampledTrajectory> motion;
  for (const Tool& tool : scene.tools) motion.push_back(sample(tool.trajectory));
  const std::size_t samples = motion.front().samples.size();
  const std::size_t stride = std::max<std::size_t>(1, samples / 64);

  // Recorded trajectory CSV, one per tool: t,px,py,pz.
  for (std::size_t i = 0; i < motion.size(); ++i) {
    std::ofstream csv(out / "trajectory_csv" / (name + "_" + scene.tools[i].name + ".csv"));
    csv << "t,px,py,pz\n";
    char row[128];
    for (std::size_t k = 0; k < motion[i].samples.size(); k += stride) {
      const ToolState& s = motion[i].samples[k];
      std::snprintf(row, sizeof row, "%.17g,%.17g,%.17g,%.17g\n", s.time, s.position.x(), s.position.y(),
                    s.position.z());
      csv << row;
    }
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
  write_profile_csv(profile, out / "profile_csv" / (name + ".csv"));

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

} // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: write_seed_corpus OUT_DIR SCENE.toml...\n";
    return 64;
  }
  const fs::path out = argv[1];
  for (const char* target : {"scene", "quantity", "trajectory_csv", "session_csv", "profile_csv", "device_protocol"})
    fs::create_directories(out / target);
  std::set<std::string> quantities;
  int scenes = 0, readable = 0;
  try {
    for (int a = 2; a < argc; ++a) {
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
            << " quantities -> " << out.string() << '\n';
  return 0;
}
