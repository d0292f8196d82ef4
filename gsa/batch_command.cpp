// `gsa batch` on the command line (docs/batch.md); the work is in gsa/batch.cpp.
#include "gsa/batch_command.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <thread>

#include "common/cli/app.hpp"
#include "common/cli/progress.hpp"
#include "common/core/error.hpp"
#include "gsa/batch.hpp"
#include "gsa/command_options.hpp"

namespace sf::gsa {

namespace {

struct BatchArgs {
  std::string parts, out, options, collect, measure;
  int jobs = 0;
};

// The --measure of the analyse options, for the table's max major strain column.
std::string measure_in(const std::vector<std::string>& words) {
  std::string m = "true";
  for (std::size_t i = 0; i < words.size(); ++i) {
    if (words[i] == "--measure" && i + 1 < words.size()) m = words[i + 1];
    if (words[i].rfind("--measure=", 0) == 0) m = words[i].substr(10);
  }
  return m;
}

std::string one_line(const BatchRow& r) {
  std::ostringstream s;
  s << r.part << ": " << r.status;
  if (r.status == "ok") {
    s << ", " << r.analysed << " of " << r.points << " points";
  } else if (!r.error.empty()) {
    s << " (" << r.error << ")";
  }
  if (r.has_time) s << " (" << std::fixed << std::setprecision(1) << r.run_time_s << " s)";
  return s.str();
}

int finish(const std::vector<BatchRow>& rows, const std::string& dir, const std::string& measure, bool quiet,
           const std::string& verb) {
  const std::string table = write_batch_table(dir, rows, measure);
  int ok = 0;
  std::vector<const BatchRow*> failed;
  for (const BatchRow& r : rows) {
    if (r.status == "ok")
      ++ok;
    else
      failed.push_back(&r);
  }
  std::ostringstream msg;
  msg << "gsa: " << ok << " of " << rows.size() << " parts " << verb;
  if (!failed.empty()) {
    msg << "; " << failed.size() << " failed or missing:";
    for (std::size_t i = 0; i < failed.size() && i < 5; ++i) msg << (i ? ", " : " ") << failed[i]->part;
    if (failed.size() > 5) msg << ", ...";
  }
  msg << "; table in " << table;
  // The failures go to stderr even with --quiet: they make the exit code 1.
  for (const BatchRow* r : failed) std::cerr << "gsa: " << one_line(*r) << "\n";
  cli::status(quiet, msg.str());
  return failed.empty() ? cli::kExitOk : cli::kExitFailure;
}

int run_batch_command(const BatchArgs& a, bool quiet) {
  if (!a.collect.empty()) {
    if (!a.out.empty() && a.out != a.collect) throw UsageError("--collect DIR builds DIR/batch.csv; --out is not used");
    if (!a.options.empty()) throw UsageError("--collect reads finished results; --options is not used");
    const std::string measure = a.measure.empty() ? "true" : a.measure;
    parse_measure(measure, "--measure");
    // With the parts given too, a part that never wrote a results folder is listed as missing.
    std::vector<std::string> names;
    if (!a.parts.empty()) {
      for (const BatchPart& p : batch_parts(a.parts)) names.push_back(p.name);
      for (const std::string& n : parts_in_results(a.collect))
        if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
    } else {
      names = parts_in_results(a.collect);
      if (names.empty())
        throw InputError(a.collect + ": no results folders (subfolders with strains.csv or summary.json) here");
    }
    std::vector<BatchRow> rows;
    for (const std::string& n : names) rows.push_back(collect_part(a.collect, n, measure));
    return finish(rows, a.collect, measure, quiet, "collected");
  }
  if (a.parts.empty()) throw UsageError("batch: give LIST_OR_FOLDER (the parts) and --out DIR, or --collect DIR");
  if (a.out.empty()) throw UsageError("batch: --out DIR is required (one results folder per part goes into it)");
  BatchOptions o;
  o.out = a.out;
  o.quiet = quiet;
  o.analyse = split_options(a.options);
  for (const std::string& w : o.analyse)
    if (w == "--out" || w == "-o" || w.rfind("--out=", 0) == 0)
      throw UsageError("--options: leave out --out; each part's results go to " + a.out + "/PART/");
  o.measure = a.measure.empty() ? measure_in(o.analyse) : a.measure;
  parse_measure(o.measure, "--measure");  // a bad measure fails before any part runs
  o.jobs = a.jobs > 0 ? a.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const std::vector<BatchPart> parts = batch_parts(a.parts);
  cli::status(quiet, "gsa: " + std::to_string(parts.size()) + " parts, " + std::to_string(o.jobs) +
                         " at a time; results in " + a.out + "/PART/, logs in " + a.out + "/logs/");
  auto bar = std::make_shared<cli::Progress>("gsa: batch", static_cast<long>(parts.size()), quiet);
  const bool lines = !quiet && !bar->enabled();  // no terminal (a log file): one line per part
  const std::vector<BatchRow> rows =
      run_batch(self_executable(), parts, o, [&](int done, int total, const BatchRow& r) {
        if (lines)
          cli::status(false, "gsa: [" + std::to_string(done) + "/" + std::to_string(total) + "] " + one_line(r));
        bar->update(done);
      });
  bar->finish();
  return finish(rows, a.out, o.measure, quiet, "analysed");
}

}  // namespace

void add_batch_command(sf::cli::Program& program) {
  const sf::cli::Program* prog = &program;
  auto args = std::make_shared<BatchArgs>();
  program.add_command(
      "batch", "Analyse many parts (one grid file each, the same options) N at a time, with a summary table batch.csv",
      [args](CLI::App& app) {
        app.add_option("parts", args->parts,
                       "A folder of grid files (*.csv, *.txt, *.tsv, *.dat; or subfolders holding grid.csv and an "
                       "optional options file), or a list file naming one grid file a line");
        app.add_option("-o,--out", args->out, "Batch folder: DIR/PART/ per part, DIR/logs/PART.log, DIR/batch.csv");
        app.add_option("-j,--jobs", args->jobs, "Parts analysed at once (default: the number of cores)");
        app.add_option("--options", args->options,
                       "Options of `gsa analyse` for every part, in one quoted string, e.g. \"--fibres 0,90 "
                       "--no-plots\"");
        app.add_option("--collect", args->collect,
                       "Only build DIR/batch.csv from results folders already in DIR (runs on other machines); "
                       "with LIST_OR_FOLDER, parts without results are listed as missing");
        app.add_option("--measure", args->measure,
                       "Strain measure of the table's max major strain: true (default), engineering or lagrangian "
                       "(default: the --measure in --options)");
      },
      [args, prog] { return run_batch_command(*args, prog->common().quiet); });
}

}  // namespace sf::gsa
