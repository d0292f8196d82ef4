#pragma once
// A stage series: several deformed states of the same marks (DIC stages, frames or images),
// read into one structure for an analysis with one undeformed fit and a deformed fit per
// stage. Two forms:
//
//  - one file per stage (read_grid_series): a reference file and stage files, or folders
//    of them, in natural order ("stage_2" before "stage_10"); each file stands for one
//    state (its current position: x, y, z, or X + u), in the format and columns of
//    GridReadOptions, joined on the id. Without a reference file, the undeformed position
//    of a mark is the reference position its first stage gives (formats with
//    displacements), or the nominal grid position with GridReadOptions::pitch.
//
//  - one file with a stage column (read_grid_series_column): a row per mark and stage.
//    The undeformed positions are the rows' reference positions (X, Y, Z, or x - u; the
//    first stage that has the mark), or the current positions of a named reference stage.
//
//   io::GridReadOptions o;
//   o.format = io::MeasurementFormat::kGom;
//   const io::GridSeries s = io::read_grid_series("ref.csv", {"stages/"}, o);
//   for (std::size_t k = 0; k < s.n_stages(); ++k) {
//     const io::GridData g = s.stage_grid(k);  // what gsa's analyse() takes
//     ...
//   }
//
// Errors are sf::InputError naming the file, line and column: a stage file with an id the
// reference lacks, a repeated id in a file (or in a stage), a folder without stage files,
// and every error of the one-file reader.

#include <string>
#include <string_view>
#include <vector>

#include "common/core/types.hpp"
#include "common/io/grid_file.hpp"

namespace sf::io {

// One deformed state of the series' marks, in GridSeries::ids order.
struct GridStage {
  std::string name;  // the file name without its extension, or the stage column's value
  // Time of the stage when its name gives one: a trailing "<number> s" or "<number>s" of a
  // file name ("surface-1_12.500 s" -> 12.5, as GOM names stage files), or a stage value
  // that is a number; NaN otherwise.
  double time = std::numeric_limits<double>::quiet_NaN();
  std::string source;                      // the file
  Points3 deformed;                        // n x 3; NaN where absent or not measured
  std::vector<std::string> where;          // n: "file:line" of the mark's row; empty where absent
  std::vector<std::uint8_t> not_measured;  // n: 1 where the format flagged the mark; empty if none
  std::vector<double> sigma;               // n: uncertainty (units), NaN where none; empty if none
};

struct GridSeries {
  std::vector<std::string> ids;
  Points3 undeformed;  // n x 3; NaN where unknown
  bool has_ij = false;
  std::vector<long> i, j;                             // n each when has_ij; kNoGridIndex where empty
  std::vector<std::string> where;                     // n: "file:line" where the undeformed position was read
  std::vector<std::uint8_t> not_measured_undeformed;  // n: 1 where flagged; empty if none
  std::vector<double> sigma_undeformed;               // n or empty
  std::string not_measured_rule;
  std::string units = "mm";
  std::vector<std::string> sources;  // the reference file (if any), then the stage files
  std::vector<std::string> notes;    // as GridData::notes
  std::vector<GridStage> stages;

  Index n_points() const { return static_cast<Index>(ids.size()); }
  std::size_t n_stages() const { return stages.size(); }
  // The undeformed state and stage k as one GridData (sources: reference, stage file).
  GridData stage_grid(std::size_t k) const;
};

// Reads a series from a reference file (may be empty: see above) and stage files or
// folders (their files with extension csv, txt, tsv or dat; not hidden ones). The stages
// are all the files found, in natural order, without the reference file.
GridSeries read_grid_series(const std::string& reference, const std::vector<std::string>& stages,
                            const GridReadOptions& options = {});

// Reads a series from one file with a stage column. reference_stage: the stage whose
// current positions are the undeformed ones (it is then not among the stages); empty: the
// rows' reference positions. Stages in natural order of their values.
GridSeries read_grid_series_column(const std::string& path, const std::string& stage_column,
                                   const GridReadOptions& options = {}, const std::string& reference_stage = "");

// The files of `paths` (files, or folders whose csv/txt/tsv/dat files are taken), in
// natural order, each once, without `exclude` (the same file by path). Throws
// sf::InputError naming a path that does not exist or a folder without such files.
std::vector<std::string> stage_files(const std::vector<std::string>& paths, const std::string& exclude = "");

// Natural order: runs of digits compare as numbers ("a2" < "a10"), the rest as text.
bool natural_less(std::string_view a, std::string_view b);

}  // namespace sf::io

namespace sf::io::detail {
// read_grid_series without the file listing: `files` as given, in that order (the
// two-file form of read_grid_file_pair is this with one file).
GridSeries build_series(const std::string& reference, const std::vector<std::string>& files,
                        const GridReadOptions& options);
}  // namespace sf::io::detail
