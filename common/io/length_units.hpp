#pragma once
// Length units of measured positions: the unit in brackets at the end of a column name
// ("coor.X [mm]"), and the factors between the units gsa converts.
//
//   unit            spellings (letter case as written)
//   millimetre      mm
//   centimetre      cm
//   metre           m
//   micrometre      µm (U+00B5), μm (U+03BC), um
//   nanometre       nm
//   inch            in, inch
//   image pixel     px, pixel, pixels, Pixel (converted only with a pixel size)

#include <optional>
#include <string>
#include <string_view>

namespace sf::io {

// A column name split into its base and the unit in brackets at its end:
// "coor.X [mm]" -> {"coor.X", "mm", true}; "x" -> {"x", "", false}; "strain [ ]" ->
// {"strain", "", true} (a dimensionless column says so with empty brackets).
struct NameAndUnit {
  std::string base;
  std::string unit;
  bool has_unit = false;
};
NameAndUnit split_unit(std::string_view name);

// Millimetres per one `unit` for the length units above; nothing for other text
// (pixels included).
std::optional<double> millimetres_per(std::string_view unit);
// True for px, pixel, pixels (any letter case).
bool is_pixel_unit(std::string_view unit);
// The length units gsa converts, for messages: "mm, cm, m, µm, nm, in".
std::string known_length_units();

}  // namespace sf::io
