#pragma once
// Physical quantities written with units in scene files ("15 mm", "200 J/m^2", "3 MPa",
// "1 mm/s", "15 deg"), converted to SI once, here.

#include <stdexcept>
#include <string>
#include <string_view>

namespace kerf {

/// The physical dimension a scene key expects.
enum class Dimension {
  dimensionless,
  length,          ///< m
  time,            ///< s
  velocity,        ///< m/s
  frequency,       ///< Hz
  angle,           ///< rad
  pressure,        ///< Pa (stress, modulus, cohesive strength)
  energy_per_area, ///< J/m^2 (fracture toughness)
  density,         ///< kg/m^3
  force,           ///< N
  force_per_length,///< N/m (stiffness, force per unit contact length)
  viscosity,       ///< Pa s (= N s/m^2)
  stiffness_per_area, ///< N/m^3 = Pa/m (an elastic foundation's stiffness per unit area)
};

/// Human name of a dimension with an example, for error messages: "a length (e.g. \"15 mm\")".
std::string describe(Dimension d);

/// A quantity that could not be parsed or has the wrong dimension; the message says what was
/// expected and what was found (the scene reader adds file:line:column and the key).
class QuantityError : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// Parses "NUMBER UNIT" (or a bare NUMBER for dimensionless quantities, and SI units are also
/// accepted written out) into SI. Units: m cm mm um µm; s ms us min h; m/s mm/s cm/s um/s;
/// Hz kHz; rad deg; Pa kPa MPa GPa N/m^2 N/mm^2; J/m^2 kJ/m^2 N/m... (see the .cpp table).
/// Throws QuantityError on anything else, on a non-finite number, and on a dimension mismatch.
double parse_quantity(std::string_view text, Dimension expected);

} // namespace kerf
