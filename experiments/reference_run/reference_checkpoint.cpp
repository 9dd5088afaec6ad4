#include "experiments/reference_run/reference_checkpoint.hpp"

#include "meshes/atomic_file.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <system_error>
#include <stdexcept>

namespace kerf {

namespace {

constexpr char checkpoint_magic[8] = {'K', 'E', 'R', 'F', 'R', 'E', 'F', '4'};
/// Version 3 (before the Kelvin–Voigt damping): no damping field; read as undamped.
constexpr char checkpoint_magic_v3[8] = {'K', 'E', 'R', 'F', 'R', 'E', 'F', '3'};
/// Version 2 (before the dynamic step): no time-integration field either; read as quasi-static.
constexpr char checkpoint_magic_v2[8] = {'K', 'E', 'R', 'F', 'R', 'E', 'F', '2'};

class Writer {
public:
  explicit Writer(std::ofstream& out) : m_out(out) {}
  void u64(std::uint64_t v) { m_out.write(reinterpret_cast<const char*>(&v), sizeof v); }
  void i32(std::int32_t v) { m_out.write(reinterpret_cast<const char*>(&v), sizeof v); }
  void f64(double v) { m_out.write(reinterpret_cast<const char*>(&v), sizeof v); }
  void str(const std::string& s) {
    u64(s.size());
    m_out.write(s.data(), static_cast<std::streamsize>(s.size()));
  }
  void vec(const Eigen::Vector3d& v) {
    for (int k = 0; k < 3; ++k) f64(v[k]);
  }

private:
  std::ofstream& m_out;
};

class Reader {
public:
  /// `bytes`: the file's size, which bounds every count read from it.
  Reader(std::ifstream& in, std::filesystem::path file, std::uint64_t bytes)
      : m_in(in), m_file(std::move(file)), m_bytes(bytes) {}
  template <class T> T pod() {
    T v{};
    m_in.read(reinterpret_cast<char*>(&v), sizeof v);
    if (!m_in) throw std::runtime_error("reference checkpoint " + m_file.string() + ": truncated");
    return v;
  }
  std::uint64_t u64() { return pod<std::uint64_t>(); }
  /// A count of items of at least `item_bytes` bytes each: no more than the bytes left in the
  /// file can hold (so a corrupt count is an error, never a huge allocation).
  std::uint64_t count(std::uint64_t item_bytes) {
    const std::uint64_t n = u64();
    const auto at = static_cast<std::uint64_t>(m_in.tellg());
    if (at > m_bytes || n > (m_bytes - at) / item_bytes)
      throw std::runtime_error("reference checkpoint " + m_file.string() + ": corrupt count");
    return n;
  }
  double f64() { return pod<double>(); }
  std::string str() {
    std::string s(count(1), '\0');
    m_in.read(s.data(), static_cast<std::streamsize>(s.size()));
    if (!m_in) throw std::runtime_error("reference checkpoint " + m_file.string() + ": truncated");
    return s;
  }
  Eigen::Vector3d vec() {
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) v[k] = f64();
    return v;
  }

private:
  std::ifstream& m_in;
  std::filesystem::path m_file;
  std::uint64_t m_bytes;
};

/// The fewest bytes one profile row takes: t, the tool name's length, position, force, mode,
/// crack extent, cost.
constexpr std::uint64_t profile_row_bytes = 8 + 8 + 3 * 8 + 3 * 8 + 4 + 8 + 8;

/// Whether run_reference can resume from this sample record: what it reads of it (the Newton
/// iterations of every record; the contact points and the energy bookkeeping of the last) is
/// there with the right type, integers within int (a JSON number outside it would convert with
/// undefined behaviour).
bool resumable_record(const nlohmann::json& s) {
  const auto count = [&](const char* key) {
    const auto it = s.find(key);
    return it != s.end() && it->is_number_integer() && it->get<std::int64_t>() >= 0 &&
           it->get<std::int64_t>() <= std::numeric_limits<int>::max();
  };
  if (!s.is_object() || !count("newton_iterations") || !count("contact_points")) return false;
  const auto energy = s.find("energy");
  if (energy == s.end()) return true;
  if (!energy->is_object()) return false;
  // EnergyBookkeeping::from_json (reference_fracture.cpp): six numbers and two lists of 3-vectors.
  for (const char* key : {"external_work_J", "stored_elastic_energy_J", "interface_energy_J", "cohesive_dissipation_J",
                          "viscous_dissipation_J", "failed_area_m2"}) {
    const auto it = energy->find(key);
    if (it == energy->end() || !it->is_number()) return false;
  }
  for (const char* key : {"contact_energy_J", "kinetic_energy_J", "cohesive_trapezoid_work_J", "damping_dissipation_J"}) { // optional (older records)
    const auto it = energy->find(key);
    if (it != energy->end() && !it->is_number()) return false;
  }
  for (const char* key : {"last_positions_m", "last_forces_on_body_N"}) {
    const auto it = energy->find(key);
    if (it == energy->end() || !it->is_array()) return false;
    for (const nlohmann::json& v : *it)
      if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number()) return false;
  }
  return true;
}

} // namespace

void write_reference_checkpoint(const ReferenceCheckpoint& c, const std::filesystem::path& file) {
  write_atomically(file, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error("reference: cannot write checkpoint " + tmp.string());
    Writer w(out);
    out.write(checkpoint_magic, sizeof checkpoint_magic);
    w.str(c.scene_sha256);
    w.i32(c.degree);
    w.i32(c.refinements);
    w.i32(c.processes);
    w.i32(c.dynamic ? 1 : 0);
    w.i32(c.damped ? 1 : 0);
    w.u64(c.indices.size());
    for (std::size_t i : c.indices) w.u64(i);
    w.u64(c.solved);
    w.f64(c.last.load_factor);
    w.vec(c.last.tool_position);
    w.u64(c.state.size());
    for (double v : c.state) w.f64(v);
    w.u64(c.profile.rows.size());
    for (const ProfileRow& r : c.profile.rows) {
      w.f64(r.t);
      w.str(r.tool);
      w.vec(r.position);
      w.vec(r.force);
      w.i32(static_cast<std::int32_t>(r.mode));
      w.f64(r.crack_extent);
      w.f64(r.cost_s);
    }
    w.str(c.samples.dump());
    w.f64(c.solve_seconds);
    w.f64(c.interface_step);
    out.flush();
    if (!out) throw std::runtime_error("reference: writing checkpoint " + tmp.string() + " failed");
  });
}

ReferenceCheckpoint read_reference_checkpoint(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("reference: cannot read checkpoint " + file.string());
  char magic[8];
  in.read(magic, sizeof magic);
  if (!in) throw std::runtime_error("reference checkpoint " + file.string() + ": not a kerf reference checkpoint");
  const bool version_2 = std::equal(magic, magic + 8, checkpoint_magic_v2);
  const bool version_3 = std::equal(magic, magic + 8, checkpoint_magic_v3);
  if (!version_2 && !version_3 && !std::equal(magic, magic + 8, checkpoint_magic))
    throw std::runtime_error("reference checkpoint " + file.string() + ": not a kerf reference checkpoint");
  std::error_code size_error;
  const std::uint64_t bytes = std::filesystem::file_size(file, size_error);
  if (size_error) throw std::runtime_error("reference: cannot read checkpoint " + file.string());
  Reader r(in, file, bytes);
  ReferenceCheckpoint c;
  c.scene_sha256 = r.str();
  c.degree = r.pod<std::int32_t>();
  c.refinements = r.pod<std::int32_t>();
  c.processes = r.pod<std::int32_t>();
  if (!version_2) {
    const auto integration = r.pod<std::int32_t>();
    if (integration != 0 && integration != 1)
      throw std::runtime_error("reference checkpoint " + file.string() + ": corrupt time integration");
    c.dynamic = integration == 1;
  }
  if (!version_2 && !version_3) {
    const auto damped = r.pod<std::int32_t>();
    if (damped != 0 && damped != 1) throw std::runtime_error("reference checkpoint " + file.string() + ": corrupt damping");
    c.damped = damped == 1;
  }
  c.indices.resize(r.count(sizeof(std::uint64_t)));
  for (std::size_t& i : c.indices) i = r.u64();
  c.solved = r.u64();
  c.last.load_factor = r.f64();
  c.last.tool_position = r.vec();
  c.state.resize(r.count(sizeof(double)));
  for (double& v : c.state) v = r.f64();
  c.profile.rows.resize(r.count(profile_row_bytes));
  for (ProfileRow& row : c.profile.rows) {
    row.t = r.f64();
    row.tool = r.str();
    row.position = r.vec();
    row.force = r.vec();
    const auto mode = r.pod<std::int32_t>();
    if (mode < 0 || mode > static_cast<std::int32_t>(InteractionMode::deformation_2))
      throw std::runtime_error("reference checkpoint " + file.string() + ": corrupt mode");
    row.mode = static_cast<InteractionMode>(mode);
    row.crack_extent = r.f64();
    row.cost_s = r.f64();
  }
  // The sample records: JSON as nlohmann::json::dump wrote it, one resumable record per solved
  // sample; anything else is a corrupt checkpoint, not a JSON exception.
  c.samples = nlohmann::json::parse(r.str(), nullptr, /*allow_exceptions=*/false);
  c.solve_seconds = r.f64();
  if (!version_2 && !version_3) {
    c.interface_step = r.f64();
    if (!(c.interface_step >= 0.0) || !std::isfinite(c.interface_step))
      throw std::runtime_error("reference checkpoint " + file.string() + ": corrupt interface step");
  }
  if (c.solved > c.indices.size())
    throw std::runtime_error("reference checkpoint " + file.string() + ": more samples solved than requested");
  if (c.samples.is_discarded() || !c.samples.is_array() || c.samples.size() != c.solved ||
      !std::all_of(c.samples.begin(), c.samples.end(), resumable_record))
    throw std::runtime_error("reference checkpoint " + file.string() + ": corrupt sample records");
  return c;
}

} // namespace kerf
