#include "formats/profile/force_profile.hpp"

#include "meshes/atomic_file.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace kerf {

void write_profile_csv(const ForceProfile& profile, const std::filesystem::path& csv) {
  write_atomically(csv, [&](const std::filesystem::path& tmp) {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(tmp.c_str(), "w"), &std::fclose);
    if (!f) throw std::runtime_error(csv.string() + ": cannot open for writing");
    std::fprintf(f.get(), "%s\n", profile_csv_header);
    for (const ProfileRow& r : profile.rows) {
      const std::string mode(to_string(r.mode));
      std::fprintf(f.get(), "%.17g,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%s,%.17g,%.17g\n", r.t, r.tool.c_str(),
                   r.position.x(), r.position.y(), r.position.z(), r.force.x(), r.force.y(), r.force.z(),
                   mode.c_str(), r.crack_extent, r.cost_s);
    }
    if (std::fflush(f.get()) != 0 || std::ferror(f.get()))
      throw std::runtime_error(csv.string() + ": write failed (disk full?)");
    std::FILE* raw = f.release();
    if (std::fclose(raw) != 0) throw std::runtime_error(csv.string() + ": write failed on close (disk full?)");
  });
}

ForceProfile read_profile_csv(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  if (!in) throw std::runtime_error(csv.string() + ": cannot open the force profile");
  static constexpr std::array<const char*, 11> columns = {"t",  "tool", "px",   "py",           "pz",    "fx",
                                                          "fy", "fz",   "mode", "crack_extent", "cost_s"};
  ForceProfile profile;
  std::string line;
  int line_number = 0;
  auto fail = [&](const std::string& what) {
    throw std::runtime_error(csv.string() + ":" + std::to_string(line_number) + ": " + what);
  };
  if (!std::getline(in, line)) fail("empty file, expected the header " + std::string(profile_csv_header));
  ++line_number;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line != profile_csv_header) fail("expected the header \"" + std::string(profile_csv_header) + "\"");
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::array<std::string, 11> field;
    std::size_t n = 0;
    std::stringstream ss(line);
    std::string item;
    while (std::getline(ss, item, ',')) {
      if (n == field.size()) fail("expected 11 columns, found more");
      field[n++] = item;
    }
    if (n != field.size()) fail("expected 11 columns, found " + std::to_string(n));
    auto number = [&](std::size_t c) {
      std::size_t used = 0;
      double v = 0.0;
      try {
        v = std::stod(field[c], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != field[c].size() || !std::isfinite(v))
        fail(std::string("column ") + columns[c] + ": expected a finite number, found \"" + field[c] + "\"");
      return v;
    };
    ProfileRow r;
    r.t = number(0);
    r.tool = field[1];
    if (r.tool.empty()) fail("column tool: empty tool name");
    r.position = {number(2), number(3), number(4)};
    r.force = {number(5), number(6), number(7)};
    const auto mode = interaction_mode_from_string(field[8]);
    if (!mode) fail("column mode: unknown mode \"" + field[8] + "\"");
    r.mode = *mode;
    r.crack_extent = number(9);
    r.cost_s = number(10);
    profile.rows.push_back(std::move(r));
  }
  return profile;
}

std::vector<const ProfileRow*> rows_of_tool(const ForceProfile& profile, const std::string& tool) {
  std::vector<const ProfileRow*> rows;
  for (const ProfileRow& r : profile.rows)
    if (r.tool == tool) rows.push_back(&r);
  return rows;
}

double tool_work(const ForceProfile& profile, const std::string& tool, std::size_t first, std::size_t last) {
  double work = 0.0;
  const ProfileRow* previous = nullptr;
  std::size_t index = 0;
  for (const ProfileRow& r : profile.rows) {
    if (r.tool != tool) continue;
    if (index > first && index <= last && previous != nullptr)
      work += 0.5 * (-r.force - previous->force).dot(r.position - previous->position);
    previous = &r;
    ++index;
  }
  return work;
}

void write_manifest(const nlohmann::json& manifest, const std::filesystem::path& path) {
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp);
    out << manifest.dump(2) << '\n';
    out.flush();
    if (!out) throw std::runtime_error(path.string() + ": write failed (disk full?)");
  });
}

} // namespace kerf
