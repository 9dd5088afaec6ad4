// Tests for formats/scene/quantity.cpp: every unit spelling converts to SI, bare numbers are
// SI, and malformed text is rejected with a message saying what was expected and what was found.
// Expected values are the SI definitions of the units (BIPM SI brochure): exact decimal factors,
// compared with a relative tolerance of a few ulps because "15 mm" is 15 * 1e-3 in floating point.

#include "formats/scene/quantity.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

namespace kerf {
namespace {

struct Case {
  const char* text;
  Dimension dimension;
  double si;
};

// clang-format off
const Case cases[] = {
  // length: SI prefixes
  {"1 m", Dimension::length, 1.0},
  {"2.5 cm", Dimension::length, 0.025},
  {"15 mm", Dimension::length, 0.015},
  {"40 um", Dimension::length, 40e-6},
  {"40 \xC2\xB5m", Dimension::length, 40e-6},   // µm (micro sign)
  {"40 \xCE\xBCm", Dimension::length, 40e-6},   // μm (Greek mu)
  // time
  {"0.5 s", Dimension::time, 0.5},
  {"20 ms", Dimension::time, 0.020},
  {"500 us", Dimension::time, 500e-6},
  {"2 min", Dimension::time, 120.0},
  {"1 h", Dimension::time, 3600.0},
  // velocity
  {"1 m/s", Dimension::velocity, 1.0},
  {"1 mm/s", Dimension::velocity, 1e-3},
  {"3 cm/s", Dimension::velocity, 0.03},
  {"250 um/s", Dimension::velocity, 250e-6},
  // frequency
  {"500 Hz", Dimension::frequency, 500.0},
  {"1 kHz", Dimension::frequency, 1000.0},
  // angle: deg = pi/180 rad
  {"0.25 rad", Dimension::angle, 0.25},
  {"15 deg", Dimension::angle, 15.0 * std::numbers::pi / 180.0},
  {"180 deg", Dimension::angle, std::numbers::pi},
  // pressure
  {"20 Pa", Dimension::pressure, 20.0},
  {"10 kPa", Dimension::pressure, 1e4},
  {"3 MPa", Dimension::pressure, 3e6},
  {"0.2 GPa", Dimension::pressure, 2e8},
  {"20.0 N/m^2", Dimension::pressure, 20.0},    // paper 002 Table 1's unit
  {"0.5 N/mm^2", Dimension::pressure, 0.5e6},
  // energy per area == force per length (J/m^2 = N/m)
  {"200 J/m^2", Dimension::energy_per_area, 200.0},
  {"0.2 kJ/m^2", Dimension::energy_per_area, 200.0}, // paper 001 footnote 1: potato
  {"300 N/m", Dimension::energy_per_area, 300.0},
  {"0.3 N/mm", Dimension::energy_per_area, 300.0},
  {"2 kN/m", Dimension::energy_per_area, 2000.0},
  {"200 J/m^2", Dimension::force_per_length, 200.0},
  {"0.2 kJ/m^2", Dimension::force_per_length, 200.0},
  {"300 N/m", Dimension::force_per_length, 300.0},
  {"0.3 N/mm", Dimension::force_per_length, 300.0},
  {"2 kN/m", Dimension::force_per_length, 2000.0},
  // density
  {"1080 kg/m^3", Dimension::density, 1080.0},
  {"1.08 g/cm^3", Dimension::density, 1080.0},
  // force
  {"0.1 N", Dimension::force, 0.1},
  {"300 mN", Dimension::force, 0.3},
  {"2 kN", Dimension::force, 2000.0},
  // viscosity: every spelling of Pa s
  {"1 Pa s", Dimension::viscosity, 1.0},
  {"1 Pa*s", Dimension::viscosity, 1.0},
  {"1 Pa.s", Dimension::viscosity, 1.0},
  {"0.5 N s/m^2", Dimension::viscosity, 0.5},   // paper 002 Table 1's unit
  // stiffness per area (N/m^3 = Pa/m): 1 N/mm^3 = 1 N / 1e-9 m^3, 1 MPa/mm = 1e6 Pa / 1e-3 m
  {"1.9e9 N/m^3", Dimension::stiffness_per_area, 1.9e9},
  {"1.9 N/mm^3", Dimension::stiffness_per_area, 1.9e9},
  {"5 Pa/m", Dimension::stiffness_per_area, 5.0},
  {"2 kPa/mm", Dimension::stiffness_per_area, 2e6},
  {"1.9 MPa/mm", Dimension::stiffness_per_area, 1.9e9},
  {"0.5 N*s/m^2", Dimension::viscosity, 0.5},
  {"3 mPa*s", Dimension::viscosity, 3e-3},
  {"3 mPa s", Dimension::viscosity, 3e-3},
  // dimensionless
  {"0.45", Dimension::dimensionless, 0.45},
};
// clang-format on

TEST(ParseQuantity, EveryUnitConvertsToSI) {
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    EXPECT_NEAR(parse_quantity(c.text, c.dimension), c.si, 4e-16 * std::abs(c.si));
  }
}

TEST(ParseQuantity, ExactValuesFromTheScenes) {
  EXPECT_DOUBLE_EQ(parse_quantity("15 mm", Dimension::length), 0.015);
  EXPECT_DOUBLE_EQ(parse_quantity("0.2 kJ/m^2", Dimension::energy_per_area), 200.0);
  EXPECT_DOUBLE_EQ(parse_quantity("15 deg", Dimension::angle), 15.0 * std::numbers::pi / 180.0);
}

TEST(ParseQuantity, BareNumbersAreSI) {
  // A bare number is SI whatever the dimension ("SI numbers" in scene files).
  EXPECT_DOUBLE_EQ(parse_quantity("0.015", Dimension::length), 0.015);
  EXPECT_DOUBLE_EQ(parse_quantity("3e6", Dimension::pressure), 3e6);
  EXPECT_DOUBLE_EQ(parse_quantity("200", Dimension::energy_per_area), 200.0);
  EXPECT_DOUBLE_EQ(parse_quantity("0.26", Dimension::angle), 0.26);
  EXPECT_DOUBLE_EQ(parse_quantity("-2", Dimension::dimensionless), -2.0);
  EXPECT_DOUBLE_EQ(parse_quantity("+2", Dimension::dimensionless), 2.0);
  EXPECT_DOUBLE_EQ(parse_quantity("1e-3", Dimension::time), 1e-3);
}

TEST(ParseQuantity, SpacingVariants) {
  for (const char* text : {"15 mm", "15mm", "  15 mm", "15 mm  ", "15\tmm", "15   mm", "1.5e1 mm", "1.5e1mm"}) {
    SCOPED_TRACE(text);
    EXPECT_DOUBLE_EQ(parse_quantity(text, Dimension::length), 0.015);
  }
  EXPECT_DOUBLE_EQ(parse_quantity("1Pa s", Dimension::viscosity), 1.0);
  EXPECT_DOUBLE_EQ(parse_quantity("-3 MPa", Dimension::pressure), -3e6); // sign kept; ranges are the reader's job
}

/// The message of the QuantityError that parsing `text` throws ("" if none is thrown).
std::string error_of(const char* text, Dimension d) {
  try {
    (void)parse_quantity(text, d);
  } catch (const QuantityError& e) {
    return e.what();
  }
  return "";
}

TEST(ParseQuantity, WrongDimensionSaysWhatWasExpectedAndFound) {
  const std::string m = error_of("3 MPa", Dimension::length);
  EXPECT_EQ(m, "expected a length (e.g. \"15 mm\"), got \"3 MPa\" (a pressure)");
  EXPECT_NE(error_of("15 mm", Dimension::time).find("expected a time"), std::string::npos);
  EXPECT_NE(error_of("1 kHz", Dimension::velocity).find("(a frequency)"), std::string::npos);
  EXPECT_NE(error_of("15 mm", Dimension::dimensionless).find("expected a plain number"), std::string::npos);
  // toughness and a force per length are one SI dimension, but a pressure is not
  EXPECT_NE(error_of("3 MPa", Dimension::energy_per_area).find("(a pressure)"), std::string::npos);
  EXPECT_NE(error_of("1 N", Dimension::force_per_length).find("(a force)"), std::string::npos);
}

TEST(ParseQuantity, RejectsMalformedText) {
  struct Bad {
    const char* text;
    Dimension dimension;
    const char* message_part;
  };
  const Bad bad[] = {
      {"15 mmm", Dimension::length, "unknown unit \"mmm\""},
      {"15 furlongs", Dimension::length, "unknown unit"},
      {"15 MM", Dimension::length, "unknown unit \"MM\""},   // units are case-sensitive (MM is not mm)
      {"mm", Dimension::length, "no number"},
      {"", Dimension::length, "got an empty value"},
      {"   ", Dimension::length, "got an empty value"},
      {"nan", Dimension::length, "not a finite number"},
      {"nan mm", Dimension::length, "not a finite number"},
      {"inf", Dimension::pressure, "not a finite number"},
      {"-inf MPa", Dimension::pressure, "not a finite number"},
      {"1e400 m", Dimension::length, "out of range"},
      {"15 mm extra", Dimension::length, "unknown unit \"mm extra\""},
      {"15 mm/", Dimension::length, "unknown unit"},
      {"+-3", Dimension::length, "no number"},
      {"0.45 %", Dimension::dimensionless, "write a plain number"},
  };
  for (const Bad& b : bad) {
    SCOPED_TRACE(b.text);
    const std::string m = error_of(b.text, b.dimension);
    ASSERT_FALSE(m.empty()) << "no error for \"" << b.text << "\"";
    EXPECT_NE(m.find(b.message_part), std::string::npos) << m;
    EXPECT_EQ(m.rfind("expected ", 0), 0u) << m; // every message starts with what was expected
  }
  // an unknown unit lists the accepted spellings of the expected dimension
  EXPECT_NE(error_of("15 mmm", Dimension::length).find("m, cm, mm, um"), std::string::npos);
}

TEST(Describe, NamesTheDimensionWithAnExample) {
  EXPECT_EQ(describe(Dimension::length), "a length (e.g. \"15 mm\")");
  EXPECT_EQ(describe(Dimension::energy_per_area), "an energy per area (e.g. \"200 J/m^2\")");
  EXPECT_EQ(describe(Dimension::viscosity), "a viscosity (e.g. \"1 Pa s\")");
  for (Dimension d : {Dimension::dimensionless, Dimension::length, Dimension::time, Dimension::velocity,
                      Dimension::frequency, Dimension::angle, Dimension::pressure, Dimension::energy_per_area,
                      Dimension::density, Dimension::force, Dimension::force_per_length, Dimension::viscosity}) {
    // every example parses as its own dimension
    const std::string text = describe(d);
    const auto open = text.find("e.g. \"") + 6;
    const std::string example = text.substr(open, text.rfind('"') - open);
    EXPECT_NO_THROW((void)parse_quantity(example, d)) << text;
  }
}

} // namespace
} // namespace kerf
