#pragma once
// A stage series in `gsa analyse` (docs/usage.md "Stage series", docs/theory/strain.md
// "Stage series"): several deformed states of the same marks (the frames of a DIC test,
// the stages of a forming sequence), read by common/io/grid_series.hpp.
//
// The undeformed state is analysed once: frame and mesh, undeformed outliers, the
// undeformed fit with its material coordinates, the undeformed noise (analyse_undeformed,
// gsa/analysis.hpp). Every stage then gets its own deformed fit against that one
// undeformed surface (analyse_deformed): its own outlier check, weights, smoothing choice,
// residuals and strains; the smoothing is chosen once (SeriesSmoothing). What does not
// depend on the stage is not redone: the mesh, the
// marks' material coordinates (so the basis rows at the marks), the penalty matrices on
// their sparsity pattern, the undeformed noise and its correlation length.
//
//   const io::GridSeries s = io::read_grid_series("", {"stages/"}, read_options);
//   check_series(s);                       // stages of another part: a clear error
//   SeriesAnalysis a(s, options);          // the undeformed stages, once; the smoothing
//   for (std::size_t k = 0; k < a.n_stages(); ++k) {
//     const GridData g = a.stage_grid(k);
//     AnalysisResult r = a.analyse_stage(k, g);   // independent of the other stages
//     ...
//   }
//
// A mark missing in a stage (not measured there, or left out of its file) gets the status
// of that (missing_deformed, not_measured) in that stage only; it keeps its strain in the
// others, and its undeformed position serves every stage.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/io/grid_series.hpp"
#include "gsa/analysis.hpp"
#include "gsa/grid.hpp"
#include "gsa/strain_measure.hpp"

namespace sf::gsa {

// Throws sf::InputError naming the stage file when a stage does not number the same marks:
// more than half of its ids are not among the first stage's (without a reference file: a
// stage of another part, or an export with other ids). A series with a reference file has
// been checked by its reader (every stage id must be in the reference).
void check_series(const io::GridSeries& series);

// How the automatic deformed smoothing is chosen in a series.
enum class SeriesSmoothing {
  kOnce,       // on the last stage (the most deformed: the sharpest strain gradients), then taken by every
               // stage with its element multipliers (--stage-smoothing once, the default): one factorisation a stage
  kEachStage,  // each stage chooses its own, as a one-state analysis would (--stage-smoothing each)
};

// Holds a reference to the series: it must outlive the analysis.
class SeriesAnalysis {
 public:
  // Runs the undeformed stages (surface method; nothing for the triangle method) and, with
  // kOnce and automatic smoothing, the last stage in full to choose the smoothing. Throws
  // as analyse() does, naming the files.
  SeriesAnalysis(const io::GridSeries& series, const AnalyseOptions& options,
                 SeriesSmoothing smoothing = SeriesSmoothing::kOnce, const ProgressCallback& progress = {});

  std::size_t n_stages() const { return series_.n_stages(); }
  // The undeformed state and stage k as one grid (what analyse_stage takes).
  GridData stage_grid(std::size_t k) const { return series_.stage_grid(k); }
  // The deformed stages of stage k (`stage`: its grid from stage_grid(k)); const: stages may
  // run in any order, and on several threads at once. Times cover this stage's own work.
  AnalysisResult analyse_stage(std::size_t k, const GridData& stage, const ProgressCallback& progress = {}) const;
  // The smoothing every stage takes (kOnce with automatic smoothing), and the stage it was chosen on.
  const std::optional<FixedSmoothing>& fixed_smoothing() const { return options_.fixed_smoothing; }
  std::size_t smoothing_stage() const { return reference_stage_; }
  // The undeformed stages (surface method), shared by every stage.
  const UndeformedStages& undeformed() const { return undeformed_; }
  double undeformed_seconds() const { return undeformed_seconds_; }

 private:
  const io::GridSeries& series_;
  AnalyseOptions options_;
  UndeformedStages undeformed_;
  double undeformed_seconds_ = 0.0;
  std::size_t reference_stage_ = 0;
  std::optional<AnalysisResult> reference_result_;  // kOnce: the stage the smoothing was chosen on
};

// Runs every stage of `analysis`, up to `ahead` of them at once on other threads (0: the
// number of cores), and hands each stage's grid and result to `take` in stage order on the
// calling thread (which writes them meanwhile). An exception of a stage is rethrown here,
// after the stages in flight have finished.
void run_stages(const SeriesAnalysis& analysis,
                const std::function<void(std::size_t k, GridData& grid, AnalysisResult& result)>& take, int ahead = 0);

// Principal strains of every point at every stage, kept while the stages run (floats: 8
// bytes a point and stage), for the strain paths.
class StagePrincipalStrains {
 public:
  explicit StagePrincipalStrains(Index n_points) : n_points_(n_points) {}
  // Adds the next stage's stretches (NaN where the point has no strain).
  void add(const AnalysisResult& stage);
  std::size_t n_stages() const { return lambda1_.size(); }
  double lambda1(std::size_t stage, Index p) const { return lambda1_[stage][static_cast<std::size_t>(p)]; }
  double lambda2(std::size_t stage, Index p) const { return lambda2_[stage][static_cast<std::size_t>(p)]; }

 private:
  Index n_points_;
  std::vector<std::vector<float>> lambda1_, lambda2_;
};

// The points whose paths are drawn: `ids` when given (an id the series lacks is an
// sf::UsageError naming it and `option`), else the `count` points of highest peak major
// stretch over the stages, each at least `min_distance` (undeformed positions, units)
// from those chosen before, so a neck is not drawn as `count` copies of one path.
std::vector<Index> choose_path_points(const StagePrincipalStrains& strains, const GridData& grid,
                                      const std::vector<std::string>& ids, int count, double min_distance,
                                      const std::string& option = "--strain-paths");
std::vector<StrainPath> strain_paths(const StagePrincipalStrains& strains, const GridData& grid,
                                     const std::vector<Index>& points, StrainMeasure measure);

}  // namespace sf::gsa
