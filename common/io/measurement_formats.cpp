#include "common/io/measurement_formats.hpp"

#include <algorithm>
#include <array>
#include <cctype>

namespace sf::io {

namespace {

std::vector<FormatSpec> make_specs() {
  std::vector<FormatSpec> specs;

  FormatSpec plain;
  plain.format = MeasurementFormat::kPlain;
  plain.name = "plain";
  plain.title = "grid file (id, X, Y, Z, x, y, z; or displacements u, v, w)";
  plain.layouts = {{{"X", "Y", "Z"}, {"x", "y", "z"}, {}, false},
                   {{"X", "Y", "Z"}, {}, {"u", "v", "w"}, false},
                   {{}, {"x", "y", "z"}, {"u", "v", "w"}, false}};
  plain.ids = {{"id"}};
  plain.sigma = {"sigma"};
  plain.i = "i";
  plain.j = "j";
  plain.invalid = InvalidRule::kNone;
  plain.invalid_text = "none (an empty or nan cell means not digitised)";
  plain.brackets = true;
  specs.push_back(plain);

  // GOM Correlate / ARAMIS Professional surface-component CSV (one file per stage):
  // x, y, z are the positions in the stage, displacement_* from the reference stage, so
  // X = x - displacement. The neutral "nodemap" export of dlr-wf/aramis-data-exporter
  // writes undeformed positions x_undef.. with u, v, w instead, under a commented header
  // ("#        ID;  x_undef [mm]; ..."; an older version of it writes "#ID,ID; x_undef
  // [mm]; ..."), and a facet it could not measure as 0, 0, 0 with nan displacements
  // (data/real/README.md: real exports of both versions).
  FormatSpec gom;
  gom.format = MeasurementFormat::kGom;
  gom.name = "gom";
  gom.title = "GOM/ZEISS ARAMIS, GOM Correlate, ZEISS INSPECT Correlate point export";
  gom.layouts = {{{}, {"x", "y", "z"}, {"displacement_x", "displacement_y", "displacement_z"}, false},
                 {{"x_undef", "y_undef", "z_undef"}, {}, {"u", "v", "w"}, false}};
  gom.ids = {{"id"}, {"ID"}, {"ID,ID"}};
  gom.invalid = InvalidRule::kEmptyCells;
  gom.invalid_text =
      "an empty or nan position or displacement cell, and a reference position of exactly 0, 0, 0 with nan "
      "displacements (a point left out of a stage file is absent)";
  gom.planar = true;
  gom.brackets = true;
  specs.push_back(gom);

  // MatchID: 2024.1 names first, then the 2023 names. Key: the subset centre in the image.
  FormatSpec matchid;
  matchid.format = MeasurementFormat::kMatchId;
  matchid.name = "matchid";
  matchid.title = "MatchID CSV export (2024.1 and 2023 column names)";
  matchid.layouts = {{{"coor.X", "coor.Y", "coor.Z"},
                      {},
                      {"disp.Horizontal Displacement U", "disp.Vertical Displacement V", "disp.Out-Of-Plane: W"},
                      false},
                     {{"x", "y", "z"}, {}, {"u", "v", "w"}, false}};
  matchid.ids = {{"Coordinates.Image X", "Coordinates.Image Y"}, {"x_pic", "y_pic"}};
  matchid.sigma = {"stats.Sigma"};
  matchid.invalid = InvalidRule::kEmptyCells;
  matchid.invalid_text = "an empty or nan position or displacement cell (a point left out of a file is absent)";
  matchid.planar = true;
  matchid.brackets = true;
  specs.push_back(matchid);

  // VIC-3D: X, Y, Z metric reference positions, U, V, W displacements; x, y the subset
  // centre in the reference image (the key); sigma the match confidence in pixels, -1
  // where the correlation failed (the row is then all zeros).
  FormatSpec vic;
  vic.format = MeasurementFormat::kVic3d;
  vic.name = "vic3d";
  vic.title = "Correlated Solutions VIC-3D CSV export";
  vic.layouts = {{{"X", "Y", "Z"}, {}, {"U", "V", "W"}, false}};
  vic.ids = {{"x", "y"}};
  vic.sigma = {"sigma"};
  vic.sigma_pixels = true;
  vic.invalid = InvalidRule::kVicSigma;
  vic.invalid_text = "sigma < 0 (the row is written as zeros); without a sigma column, a row of zeros";
  vic.planar = true;
  vic.brackets = false;
  specs.push_back(vic);

  // DICe: stereo results in model coordinates, else 2-D results in image pixels.
  FormatSpec dice;
  dice.format = MeasurementFormat::kDice;
  dice.name = "dice";
  dice.title = "Sandia DICe output (DICe_solution_N.txt)";
  dice.layouts = {{{"MODEL_COORDINATES_X", "MODEL_COORDINATES_Y", "MODEL_COORDINATES_Z"},
                   {},
                   {"MODEL_DISPLACEMENT_X", "MODEL_DISPLACEMENT_Y", "MODEL_DISPLACEMENT_Z"},
                   false},
                  {{"COORDINATE_X", "COORDINATE_Y", ""}, {}, {"DISPLACEMENT_X", "DISPLACEMENT_Y", ""}, true}};
  dice.ids = {{"SUBSET_ID"}, {"COORDINATE_X", "COORDINATE_Y"}};
  dice.sigma = {"SIGMA"};
  dice.sigma_pixels = true;
  dice.invalid = InvalidRule::kDiceMatch;
  dice.invalid_text =
      "MATCH != 0, or without a MATCH column SIGMA < 0 (the subset centre stays the reference position)";
  dice.planar = true;
  dice.brackets = false;
  specs.push_back(dice);
  return specs;
}

}  // namespace

const std::vector<FormatSpec>& format_specs() {
  static const std::vector<FormatSpec> all = make_specs();
  return all;
}

const FormatSpec& format_spec(MeasurementFormat format) {
  for (const FormatSpec& s : format_specs())
    if (s.format == format) return s;
  return format_specs().front();
}

std::optional<MeasurementFormat> format_by_name(std::string_view name) {
  std::string n(name);
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  static const std::array<std::pair<std::string_view, MeasurementFormat>, 11> kNames = {{
      {"auto", MeasurementFormat::kAuto},
      {"plain", MeasurementFormat::kPlain},
      {"grid", MeasurementFormat::kPlain},
      {"gom", MeasurementFormat::kGom},
      {"aramis", MeasurementFormat::kGom},
      {"correlate", MeasurementFormat::kGom},
      {"zeiss", MeasurementFormat::kGom},
      {"matchid", MeasurementFormat::kMatchId},
      {"vic3d", MeasurementFormat::kVic3d},
      {"vic", MeasurementFormat::kVic3d},
      {"dice", MeasurementFormat::kDice},
  }};
  for (const auto& [text, format] : kNames)
    if (n == text) return format;
  return std::nullopt;
}

std::string format_names() {
  std::string out = "auto";
  for (const FormatSpec& s : format_specs()) out += ", " + s.name;
  return out;
}

}  // namespace sf::io
