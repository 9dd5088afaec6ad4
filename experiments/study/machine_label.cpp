#include "experiments/study/machine_label.hpp"

#include <fstream>
#include <sstream>
#include <thread>

namespace kerf {

namespace {
std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}
} // namespace

std::string cpu_model_name(const std::string& cpuinfo) {
  for (const char* key : {"model name", "Hardware", "Processor"}) {
    std::istringstream lines(cpuinfo);
    std::string line;
    while (std::getline(lines, line)) {
      const auto colon = line.find(':');
      if (colon == std::string::npos || trimmed(line.substr(0, colon)) != key) continue;
      const std::string value = trimmed(line.substr(colon + 1));
      if (!value.empty()) return value;
    }
  }
  return "";
}

std::string machine_label() {
  std::ifstream in("/proc/cpuinfo");
  std::stringstream text;
  text << in.rdbuf();
  std::string model = cpu_model_name(text.str());
  if (model.empty()) model = "unknown CPU";
  const unsigned cores = std::thread::hardware_concurrency();
  return model + ", " + std::to_string(cores) + (cores == 1 ? " core" : " cores");
}

} // namespace kerf
