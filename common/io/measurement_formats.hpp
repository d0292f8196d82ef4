#pragma once
// The column layouts of measuring-system exports that the grid reader knows by name
// (`gsa analyse --format NAME`, docs/usage.md "Input formats"). Each preset says which
// columns hold the points' key, their positions and displacements, an uncertainty, and
// how the system marks a point it could not measure. What is known about each export,
// with sources and confidence, is in the research notes the presets were built from;
// where they are unsure, docs/usage.md says so and names the option that overrides.
//
//   name     system                                    key                 positions
//   plain    the grid file of CONTRACT.md              id (else row)       X,Y,Z and x,y,z (or u,v,w)
//   gom      GOM/ZEISS ARAMIS, Correlate, INSPECT      id                  x,y,z current + displacement_*
//   matchid  MatchID CSV (2024.1 names, 2023 names)    image x, y          coor.X.. (2023: x..) + disp..
//   vic3d    Correlated Solutions VIC-3D CSV           x, y (image)        X,Y,Z reference + U,V,W
//   dice     Sandia DICe DICe_solution_N.txt           SUBSET_ID           MODEL_COORDINATES_* + MODEL_DISPLACEMENT_*,
//                                                                          else COORDINATE_X/Y + DISPLACEMENT_X/Y (pixels)
//
// A layout names two of the three triples: reference positions X (before forming),
// current positions x (after) and displacements u = x - X. The third follows.

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sf::io {

// kAuto: found from the header by the reader (grid_rows.hpp): the one preset whose
// columns and key are all there, else plain.
enum class MeasurementFormat { kPlain, kGom, kMatchId, kVic3d, kDice, kAuto };

// What the position columns of a layout with displacements hold (GridReadOptions::positions).
enum class Positions {
  kAsFormat,   // as the preset says
  kReference,  // reference positions X: the current position is x = X + u
  kCurrent,    // current positions x: the reference position is X = x - u
};

// How a format marks a point it could not measure, besides leaving its row out (a point
// absent from a file is simply absent from that state).
enum class InvalidRule {
  kNone,        // plain: an empty or nan cell means "not digitised" (status missing_*)
  kEmptyCells,  // an empty or nan position or displacement cell: not measured in that state;
                // gom only: reference positions of exactly 0, 0, 0 beside nan displacements
                // are not measured in either (the neutral ARAMIS nodemap's failed facet)
  kVicSigma,    // sigma < 0 (VIC-3D writes such a row as zeros); without a sigma column, a
                // row whose positions and displacements are all exactly 0
  kDiceMatch,   // MATCH != 0, or without MATCH, SIGMA < 0; the reference position (the subset
                // centre) stays valid, the displacements are stale and not read
};

// Column names of the x, y, z components; all empty: the layout has no such triple.
using ColumnTriple = std::array<std::string, 3>;

struct FormatLayout {
  ColumnTriple reference, current, displacement;
  bool pixels = false;  // positions and displacements are in image pixels (unless a column says)
};

struct FormatSpec {
  MeasurementFormat format = MeasurementFormat::kPlain;
  std::string name;                           // the --format value
  std::string title;                          // e.g. "Correlated Solutions VIC-3D CSV export"
  std::vector<FormatLayout> layouts;          // tried in order: the first found in the header is read
  std::vector<std::vector<std::string>> ids;  // id column sets, tried in order
  std::vector<std::string> sigma;             // uncertainty column names, tried in order
  bool sigma_pixels = false;                  // sigma is in pixels unless the column says
  std::string i, j;                           // grid row and column ("" = none)
  InvalidRule invalid = InvalidRule::kNone;
  std::string invalid_text;  // the rule in words, e.g. "sigma < 0 (VIC-3D: no correlation)"
  bool planar = false;       // the z columns may be missing: then Z = z = 0 (2-D correlation)
  bool brackets = false;     // names carry units in brackets ("coor.X [mm]")
};

// The preset of a format; plain's for kAuto (which the reader resolves first).
const FormatSpec& format_spec(MeasurementFormat format);
// The presets, plain first.
const std::vector<FormatSpec>& format_specs();
// The format of a --format value: auto, plain, gom (also aramis, correlate, zeiss),
// matchid, vic3d (also vic), dice; letter case ignored. Nothing for other text.
std::optional<MeasurementFormat> format_by_name(std::string_view name);
// "auto, plain, gom, matchid, vic3d, dice", for messages.
std::string format_names();

}  // namespace sf::io
