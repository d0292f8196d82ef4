#pragma once
// The results of a stage series (gsa/series.hpp), as `gsa analyse --stages ...` writes
// them (docs/usage.md "Stage series"). Beside the one-state results of the LAST stage
// (strains.csv, undeformed.vtp, deformed.vtp, pictures: what `gsa plot` redraws):
//
//   series_strains.csv   one long table, a row per point and stage (stage, stage_name,
//                        time, id, status, strains, residual, flag): filter or pivot it
//                        by stage in a spreadsheet, group it by id for a point's history
//   stages/stage_NNN.vtp the fitted deformed surface of stage NNN (000 = first) with the
//                        strain fields, as deformed.vtp holds them
//   series.pvd           the ParaView time series of those surfaces (time: the stage's
//                        time where its name or stage value gives one, else its index)
//   strain_paths.csv     major and minor strain of the path points at every stage
//   summary.json         "series": an entry per stage (counts by status, fit residuals,
//                        smoothing, noise, strain ranges, times) and the path points
//
//   SeriesWriter w(out, series, options);
//   for each stage k: w.add_stage(k, grid_k, result_k);
//   nlohmann::json j = w.finish(paths);   // series.pvd, strain_paths.csv; the summary part

#include <nlohmann/json.hpp>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "common/io/grid_series.hpp"
#include "gsa/analysis.hpp"
#include "gsa/output.hpp"
#include "gsa/strain_measure.hpp"

namespace sf::io {
class AtomicOutputDir;
}

namespace sf::gsa {

struct AnalyseFlags;

// File name of stage k's surface: "stages/stage_007.vtp" (three digits at least).
std::string stage_surface_name(std::size_t k, std::size_t n_stages);
// Column names of series_strains.csv, in order.
std::vector<std::string> series_strain_columns();

class SeriesWriter {
 public:
  // Opens series_strains.csv in `out`. `surfaces`: write stages/stage_NNN.vtp and series.pvd.
  SeriesWriter(io::AtomicOutputDir& out, const io::GridSeries& series, const OutputOptions& options,
               bool surfaces = true);
  ~SeriesWriter();
  SeriesWriter(const SeriesWriter&) = delete;
  SeriesWriter& operator=(const SeriesWriter&) = delete;

  // Stage k's rows, surface and summary entry.
  void add_stage(std::size_t k, const GridData& grid, const AnalysisResult& result);
  // series.pvd and strain_paths.csv; returns the "series" part of summary.json.
  // `smoothing`: how the smoothing was chosen, in words.
  nlohmann::json finish(const std::vector<StrainPath>& paths, double undeformed_seconds,
                        const std::string& smoothing = "");

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// `gsa analyse` on a series (--stages, or GRID --stage-column): reads, analyses stage by
// stage (a status line each), writes the results above and the pictures of the last stage
// with the strain paths. Returns the exit code.
int run_analyse_series(const AnalyseFlags& flags, bool quiet);

}  // namespace sf::gsa
