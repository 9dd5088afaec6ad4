#include "realtime/phenomena.hpp"

namespace kerf {

std::string_view to_string(Phenomenon p) {
  switch (p) {
  case Phenomenon::deformation: return "deformation";
  case Phenomenon::cutting: return "cutting";
  case Phenomenon::tearing: return "tearing";
  case Phenomenon::friction: return "friction";
  case Phenomenon::layers: return "layers";
  }
  return "?";
}

std::optional<Phenomenon> phenomenon_from_string(std::string_view name) {
  for (Phenomenon p : all_phenomena)
    if (to_string(p) == name) return p;
  return std::nullopt;
}

std::string PhenomenonSet::to_string() const {
  std::string out;
  for (Phenomenon p : all_phenomena) {
    if (!contains(p)) continue;
    if (!out.empty()) out += ", ";
    out += kerf::to_string(p);
  }
  return out;
}

} // namespace kerf
