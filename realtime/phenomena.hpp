#pragma once
// The phenomena a scene declares and a model covers ("model only what a scene requires",
// ../shared/DESIGN.md).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace kerf {

enum class Phenomenon : std::uint8_t { deformation, cutting, tearing, friction, layers };

inline constexpr Phenomenon all_phenomena[] = {Phenomenon::deformation, Phenomenon::cutting,
                                               Phenomenon::tearing, Phenomenon::friction,
                                               Phenomenon::layers};

/// The scene-file spelling: "deformation", "cutting", "tearing", "friction", "layers".
std::string_view to_string(Phenomenon p);
std::optional<Phenomenon> phenomenon_from_string(std::string_view name);

/// A small set of phenomena (value type).
class PhenomenonSet {
public:
  constexpr PhenomenonSet() = default;
  constexpr PhenomenonSet(std::initializer_list<Phenomenon> list) {
    for (Phenomenon p : list) insert(p);
  }
  constexpr void insert(Phenomenon p) { m_bits |= bit(p); }
  [[nodiscard]] constexpr bool contains(Phenomenon p) const { return (m_bits & bit(p)) != 0; }
  [[nodiscard]] constexpr bool empty() const { return m_bits == 0; }
  /// The phenomena of this set that `other` lacks.
  [[nodiscard]] constexpr PhenomenonSet missing_from(PhenomenonSet other) const {
    PhenomenonSet s;
    s.m_bits = static_cast<std::uint8_t>(m_bits & ~other.m_bits);
    return s;
  }
  friend constexpr bool operator==(PhenomenonSet, PhenomenonSet) = default;
  /// Comma-separated names, e.g. "deformation, cutting".
  [[nodiscard]] std::string to_string() const;

private:
  static constexpr std::uint8_t bit(Phenomenon p) { return static_cast<std::uint8_t>(1u << static_cast<unsigned>(p)); }
  std::uint8_t m_bits = 0;
};

} // namespace kerf
