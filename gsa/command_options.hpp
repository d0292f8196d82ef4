#pragma once
// The command layer of gsa: the flags of the command line, as typed, turned into the
// fields of the library's option structs (AnalyseOptions, OutputOptions, GridReadOptions).
// The library names fields in its errors; here they become the user's flags:
// "--smoothing-scale: must be > 0, found 0". Errors are sf::UsageError (exit code 2).

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "gsa/analysis.hpp"
#include "gsa/grid.hpp"
#include "gsa/output.hpp"
#include "gsa/plots.hpp"
#include "gsa/strain_measure.hpp"

namespace sf::gsa {

// The flags of `gsa analyse` (docs/usage.md); NaN weights are "not given".
struct AnalyseFlags {
  std::string grid, undeformed, deformed, out;
  std::string method = "surface", penalty = "jumps", smoothing_rule = "noise-model", elements, mesh, columns,
              delimiter = "auto", fibres, units = "mm";
  // Reading (docs/usage.md "Input formats"); NaN: not given.
  std::string format = "auto", id, positions, decimal = "auto";
  int skip_lines = 0, header_line = 0;
  double pitch = std::numeric_limits<double>::quiet_NaN(), pixel_size = std::numeric_limits<double>::quiet_NaN();
  // Smoothing weights: empty = not given (automatic); a given NaN or infinity is refused.
  std::optional<double> alpha, beta, gamma, delta;
  double outlier_sigma = 4.5, smoothing_scale = 1.0;
  bool no_local_smoothing = false;
  int sample = 0;
  bool no_plots = false;
  std::string measure = "true", size = "1200x900", view = "auto", flc;  // pictures
  bool no_sigma_weights = false;                                        // --no-sigma-weights
  // Stage series (gsa/series_output.hpp): --stages files/folders, or GRID --stage-column.
  std::vector<std::string> stages;
  std::string stage_column, reference_stage, path_ids, stage_smoothing = "once";
  int strain_paths = 5;
  // Press-shop outputs (docs/usage.md): mid-surface strains, forming-limit assessment,
  // sections. Empty optionals: not given.
  std::optional<double> thickness;  // --thickness, initial sheet thickness (length unit, mm)
  std::string grid_face = "top";    // --grid-face
  std::optional<double> flc_n;      // --flc-n: Keeler-Brazier curve (with --thickness)
  std::optional<double> flc0;       // --flc0: plane-strain limit, standard shape
  double necking_margin = 0.10, thinning_limit = 30.0, min_stretch = 0.02;
  std::vector<std::string> sections;  // --section (repeatable)
  bool neck = false;                  // --neck
};

// --method, --penalty, --mesh/--elements, --alpha.. --delta, --smoothing-scale,
// --outlier-sigma, --fibres; validated, errors naming the flag.
AnalyseOptions analyse_options(const AnalyseFlags& flags);
// --units, --sample, --measure and --flc (the curve is read here: a missing or bad file is
// an sf::InputError naming it, with or without pictures); validated, errors naming the flag.
OutputOptions output_options(const AnalyseFlags& flags);
// --size, --view of the pictures.
PlotOptions plot_options(const std::string& size, const std::string& view);
// "true" (also "logarithmic", "natural"), "engineering" or "lagrangian" (also "green"), any
// letter case; errors name `option`.
StrainMeasure parse_measure(const std::string& text, const std::string& option = "--measure");
// --format, --columns, --id, --positions, --delimiter, --decimal, --skip-lines,
// --header-line, --units, --pixel-size, --pitch; validated, errors naming the flag.
GridReadOptions grid_read_options(const AnalyseFlags& flags);
// "--format": auto, plain, gom (also aramis, correlate, zeiss), matchid, vic3d (also vic), dice.
io::MeasurementFormat parse_format(const std::string& text);
// "--id": column names separated by commas (the id joins their cells with '_'), or "row".
std::vector<std::string> parse_id_columns(const std::string& text);

// Throws sf::UsageError naming --units for a unit text that would break the outputs (line
// breaks or other control characters, commas, quotes, more than 40 characters).
void check_units_text(const std::string& units);

// The flag that sets a field of AnalyseOptions or OutputOptions ("smoothing.scale" ->
// "--smoothing-scale"); the field itself when no flag sets it.
std::string flag_of_field(const std::string& field);

// "--columns" text "X=x0,Y=y0,u=disp_x" -> key -> column name (keys: io::kGridColumnKeys).
// A name holding a comma is double-quoted: x="eps [%, technical]".
std::map<std::string, std::string> parse_column_map(const std::string& text);
// "--delimiter": one character, or "auto" (io::kDetectDelimiter), "tab", "comma",
// "semicolon", "space" (runs of blanks).
char parse_delimiter(const std::string& text);

}  // namespace sf::gsa
