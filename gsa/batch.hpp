#pragma once
// `gsa batch`: many parts (one grid file each, the same options) through `gsa analyse`,
// N at a time, each part in its own process writing its own results folder DIR/PART/,
// and one summary table DIR/batch.csv (docs/batch.md).
//
// Each part runs as a child process of this executable (`gsa analyse ...`), so a part
// that fails, or even crashes, cannot take the others with it, and every part writes
// exactly what `gsa analyse` writes. The summary table is built from the results
// folders afterwards (collect_batch), the same code `gsa batch --collect DIR` runs on
// folders written by other machines (a Slurm job array, GNU parallel over ssh).

#include <functional>
#include <string>
#include <vector>

namespace sf::gsa {

struct BatchPart {
  std::string name;                        // results folder name under DIR, and the `part` column of batch.csv
  std::string input;                       // the grid file
  std::vector<std::string> extra_options;  // from an `options` file beside a grid.csv (as data/gsa/*/)
};

// The parts of LIST_OR_FOLDER:
//  - a folder: every grid file directly in it (*.csv, *.txt, *.tsv, *.dat; not hidden),
//    named by the file's stem, and every subfolder holding a grid.csv, named by the
//    subfolder (with the words of its `options` file, if any, as extra options);
//  - a file: a list, one grid file per line (relative paths are relative to the list's
//    folder; blank lines and lines starting with '#' skipped), named by the stem, or
//    by the folder for a file called grid.csv.
// Parts come sorted by name (folder) or in list order. Throws sf::InputError naming the
// list and line for a missing file, two parts of one name, or no part at all.
std::vector<BatchPart> batch_parts(const std::string& list_or_folder);

// Splits an --options text into words: blanks separate, "..." and '...' quote.
// Throws sf::UsageError for an unclosed quote.
std::vector<std::string> split_options(const std::string& text);

struct BatchOptions {
  std::string out;                   // DIR
  int jobs = 1;                      // parts at once
  std::vector<std::string> analyse;  // options passed to every `gsa analyse`
  std::string measure = "true";      // strain measure of the table's max major strain
  bool quiet = false;
};

// One row of batch.csv.
struct BatchRow {
  std::string part, input, status;  // status: ok, failed, missing
  long points = -1, analysed = -1;  // -1: unknown
  double max_major = 0, min_thickness_change_pct = 0, worst_flc_margin = 0, run_time_s = 0;
  bool has_strains = false, has_flc = false, has_time = false;
  std::string results, error;
};

// Reads DIR/PART/ (summary.json, strains.csv) into a row; a part without a results folder
// gets status "missing" (or the failure of its log DIR/logs/PART.log). Never throws for a
// bad folder: its problem goes into `error` with status "failed".
BatchRow collect_part(const std::string& dir, const std::string& part, const std::string& measure);

// The parts found in DIR: every subfolder holding a summary.json or strains.csv, sorted,
// plus the names of DIR/logs/*.log without a folder (failed runs).
std::vector<std::string> parts_in_results(const std::string& dir);

// Writes DIR/batch.csv (atomically) and returns its path.
std::string write_batch_table(const std::string& dir, const std::vector<BatchRow>& rows, const std::string& measure);

// Runs the parts (children: `EXE --quiet analyse INPUT --out DIR/PART OPTIONS...`, their
// stdout and stderr in DIR/logs/PART.log), collects the table and returns the rows.
// `executable` is this program; `progress` hears (done, total, row) after each part.
// Throws sf::UsageError (exit code 2) when a part's `gsa analyse` rejects the options:
// then every part would, and the batch stops launching new parts.
std::vector<BatchRow> run_batch(const std::string& executable, const std::vector<BatchPart>& parts,
                                const BatchOptions& options,
                                const std::function<void(int, int, const BatchRow&)>& progress);

// The path of the running executable (/proc/self/exe).
std::string self_executable();

}  // namespace sf::gsa
