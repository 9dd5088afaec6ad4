// Units of scene quantities to SI (quantity.hpp). One table of spellings; J/m^2 and N/m share a
// dimension. A bare number is SI.

#include "formats/scene/quantity.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <numbers>
#include <string>
#include <system_error>

namespace kerf {

namespace {

/// One spelling of a unit: its dimension and the factor that takes it to SI.
struct UnitSpelling {
  std::string_view text;
  Dimension dimension;
  double to_si;
};

constexpr double pi = std::numbers::pi;

// J/m^2 and N/m are the same SI dimension (kg s^-2): fracture toughness and force per unit
// length (paper 001 §4.3: J_c and f_r are compared directly) share these spellings.
// clang-format off
constexpr std::array units{
  // length [m]
  UnitSpelling{"m", Dimension::length, 1.0},
  UnitSpelling{"cm", Dimension::length, 1e-2},
  UnitSpelling{"mm", Dimension::length, 1e-3},
  UnitSpelling{"um", Dimension::length, 1e-6},
  UnitSpelling{"\xC2\xB5m", Dimension::length, 1e-6},   // µm, micro sign U+00B5
  UnitSpelling{"\xCE\xBCm", Dimension::length, 1e-6},   // μm, Greek mu U+03BC
  // time [s]
  UnitSpelling{"s", Dimension::time, 1.0},
  UnitSpelling{"ms", Dimension::time, 1e-3},
  UnitSpelling{"us", Dimension::time, 1e-6},
  UnitSpelling{"\xC2\xB5s", Dimension::time, 1e-6},
  UnitSpelling{"min", Dimension::time, 60.0},
  UnitSpelling{"h", Dimension::time, 3600.0},
  // velocity [m/s]
  UnitSpelling{"m/s", Dimension::velocity, 1.0},
  UnitSpelling{"cm/s", Dimension::velocity, 1e-2},
  UnitSpelling{"mm/s", Dimension::velocity, 1e-3},
  UnitSpelling{"um/s", Dimension::velocity, 1e-6},
  UnitSpelling{"\xC2\xB5m/s", Dimension::velocity, 1e-6},
  // frequency [Hz]
  UnitSpelling{"Hz", Dimension::frequency, 1.0},
  UnitSpelling{"kHz", Dimension::frequency, 1e3},
  // angle [rad]
  UnitSpelling{"rad", Dimension::angle, 1.0},
  UnitSpelling{"deg", Dimension::angle, pi / 180.0},
  // pressure [Pa]
  UnitSpelling{"Pa", Dimension::pressure, 1.0},
  UnitSpelling{"kPa", Dimension::pressure, 1e3},
  UnitSpelling{"MPa", Dimension::pressure, 1e6},
  UnitSpelling{"GPa", Dimension::pressure, 1e9},
  UnitSpelling{"N/m^2", Dimension::pressure, 1.0},
  UnitSpelling{"N/mm^2", Dimension::pressure, 1e6},
  // energy per area [J/m^2] = force per length [N/m]
  UnitSpelling{"J/m^2", Dimension::energy_per_area, 1.0},
  UnitSpelling{"kJ/m^2", Dimension::energy_per_area, 1e3},
  UnitSpelling{"N/m", Dimension::energy_per_area, 1.0},
  UnitSpelling{"N/mm", Dimension::energy_per_area, 1e3},
  UnitSpelling{"kN/m", Dimension::energy_per_area, 1e3},
  // density [kg/m^3]
  UnitSpelling{"kg/m^3", Dimension::density, 1.0},
  UnitSpelling{"g/cm^3", Dimension::density, 1e3},
  // force [N]
  UnitSpelling{"N", Dimension::force, 1.0},
  UnitSpelling{"mN", Dimension::force, 1e-3},
  UnitSpelling{"kN", Dimension::force, 1e3},
  // viscosity [Pa s]
  UnitSpelling{"Pa s", Dimension::viscosity, 1.0},
  UnitSpelling{"Pa*s", Dimension::viscosity, 1.0},
  UnitSpelling{"Pa.s", Dimension::viscosity, 1.0},
  UnitSpelling{"N s/m^2", Dimension::viscosity, 1.0},
  UnitSpelling{"N*s/m^2", Dimension::viscosity, 1.0},
  UnitSpelling{"mPa s", Dimension::viscosity, 1e-3},
  UnitSpelling{"mPa*s", Dimension::viscosity, 1e-3},
  UnitSpelling{"mPa.s", Dimension::viscosity, 1e-3},
  // stiffness per area [N/m^3] = pressure per length [Pa/m]
  UnitSpelling{"N/m^3", Dimension::stiffness_per_area, 1.0},
  UnitSpelling{"N/mm^3", Dimension::stiffness_per_area, 1e9},
  UnitSpelling{"Pa/m", Dimension::stiffness_per_area, 1.0},
  UnitSpelling{"kPa/mm", Dimension::stiffness_per_area, 1e6},
  UnitSpelling{"MPa/mm", Dimension::stiffness_per_area, 1e9},
};
// clang-format on

/// energy_per_area and force_per_length are one SI dimension; everything else is itself.
Dimension si_class(Dimension d) {
  return d == Dimension::force_per_length ? Dimension::energy_per_area : d;
}

/// "a length", "an angle", ... (no example): for what was found.
std::string_view noun(Dimension d) {
  switch (d) {
  case Dimension::dimensionless: return "a plain number";
  case Dimension::length: return "a length";
  case Dimension::time: return "a time";
  case Dimension::velocity: return "a velocity";
  case Dimension::frequency: return "a frequency";
  case Dimension::angle: return "an angle";
  case Dimension::pressure: return "a pressure";
  case Dimension::energy_per_area: return "an energy per area";
  case Dimension::density: return "a density";
  case Dimension::force: return "a force";
  case Dimension::force_per_length: return "a force per length";
  case Dimension::viscosity: return "a viscosity";
  case Dimension::stiffness_per_area: return "a stiffness per area";
  }
  return "a quantity";
}

std::string_view example(Dimension d) {
  switch (d) {
  case Dimension::dimensionless: return "0.45";
  case Dimension::length: return "15 mm";
  case Dimension::time: return "0.5 s";
  case Dimension::velocity: return "1 mm/s";
  case Dimension::frequency: return "1 kHz";
  case Dimension::angle: return "15 deg";
  case Dimension::pressure: return "3 MPa";
  case Dimension::energy_per_area: return "200 J/m^2";
  case Dimension::density: return "1080 kg/m^3";
  case Dimension::force: return "0.1 N";
  case Dimension::force_per_length: return "300 N/m";
  case Dimension::viscosity: return "1 Pa s";
  case Dimension::stiffness_per_area: return "1.9e9 N/m^3";
  }
  return "";
}

/// The accepted spellings for one dimension, comma-separated: for "unknown unit" messages.
std::string spellings(Dimension d) {
  std::string out;
  for (const UnitSpelling& u : units) {
    if (si_class(u.dimension) != si_class(d)) continue;
    if (!out.empty()) out += ", ";
    out += u.text;
  }
  return out;
}

bool is_space(char c) { return c == ' ' || c == '\t'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

[[noreturn]] void fail(Dimension expected, std::string_view text, std::string_view why) {
  std::string msg = "expected " + describe(expected) + ", got ";
  if (trim(text).empty())
    msg += "an empty value";
  else
    msg += "\"" + std::string(text) + "\"";
  if (!why.empty()) msg += std::string(" (") + std::string(why) + ")";
  throw QuantityError(msg);
}

} // namespace

std::string describe(Dimension d) {
  std::string out(noun(d));
  out += " (e.g. \"";
  out += example(d);
  out += "\")";
  return out;
}

double parse_quantity(std::string_view text, Dimension expected) {
  const std::string_view s = trim(text);
  if (s.empty()) fail(expected, text, "");

  // The number: std::from_chars does not take a leading '+', so strip one here.
  std::string_view rest = s;
  bool plus = false;
  if (rest.front() == '+') {
    plus = true;
    rest.remove_prefix(1);
    if (!rest.empty() && rest.front() == '-') fail(expected, text, "no number");
  }
  double value = 0.0;
  const auto [end, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), value);
  if (ec == std::errc::result_out_of_range) fail(expected, text, "number out of range");
  if (ec != std::errc{} || (plus && rest.empty())) fail(expected, text, "no number");
  if (!std::isfinite(value)) fail(expected, text, "not a finite number");

  const std::string_view unit = trim(std::string_view(end, static_cast<std::size_t>(rest.data() + rest.size() - end)));
  // A bare number is SI for every dimension (how scene files give "SI numbers").
  if (unit.empty()) return value;

  for (const UnitSpelling& u : units) {
    if (u.text != unit) continue;
    if (si_class(u.dimension) != si_class(expected)) fail(expected, text, noun(u.dimension));
    const double si = value * u.to_si;
    if (!std::isfinite(si)) fail(expected, text, "number out of range");
    return si;
  }
  std::string why = "unknown unit \"" + std::string(unit) + "\"";
  if (expected == Dimension::dimensionless)
    why += "; write a plain number";
  else
    why += "; " + std::string(noun(expected).substr(noun(expected).find(' ') + 1)) +
           " units: " + spellings(expected);
  fail(expected, text, why);
}

} // namespace kerf
