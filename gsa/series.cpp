#include "gsa/series.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <future>
#include <thread>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "common/core/error.hpp"

namespace sf::gsa {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

void check_series(const io::GridSeries& s) {
  if (s.n_stages() == 0)
    throw InputError((s.sources.empty() ? std::string("series") : s.sources.front()) + ": no stages");
  // With a reference file (or stage) every stage id is the reference's: the reader checked.
  if (s.sources.size() == s.n_stages() + 1) return;  // sources: the reference file, then the stage files
  const io::GridStage& first = s.stages.front();
  const Index n = s.n_points();
  for (std::size_t k = 1; k < s.n_stages(); ++k) {
    const io::GridStage& st = s.stages[k];
    if (st.source == first.source) continue;  // one file with a stage column: ids are the file's
    Index present = 0, fresh = 0;
    Index example = -1;
    for (Index p = 0; p < n; ++p) {
      const auto pp = static_cast<std::size_t>(p);
      if (st.where[pp].empty()) continue;
      ++present;
      if (first.where[pp].empty()) {
        ++fresh;
        if (example < 0) example = p;
      }
    }
    if (present > 0 && 2 * fresh > present)
      throw InputError(fmt::format(
          "{}: {} of its {} point ids are not in the first stage file {} (e.g. '{}'): every stage of a series must "
          "number the same points; is this a stage of another part, or an export with other ids?",
          st.source, fresh, present, first.source, s.ids[static_cast<std::size_t>(example)]));
  }
}

SeriesAnalysis::SeriesAnalysis(const io::GridSeries& series, const AnalyseOptions& options, SeriesSmoothing smoothing,
                               const ProgressCallback& progress)
    : series_(series), options_(options) {
  options_.validate();
  options_.fixed_smoothing.reset();
  if (series.n_stages() == 0) throw InputError("stage series: no stages");
  if (options_.method != Method::kSurface) return;
  const auto t0 = std::chrono::steady_clock::now();
  // Stage 0's grid carries the undeformed positions and sigmas every stage shares.
  undeformed_ = analyse_undeformed(series.stage_grid(0), options_, progress);
  undeformed_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (smoothing != SeriesSmoothing::kOnce || !options_.smoothing.chooses_by_gcv()) return;
  // The last stage, in full: its choice (and local relaxation, where a neck is) for all.
  reference_stage_ = series.n_stages() - 1;
  AnalysisResult r = analyse_deformed(undeformed_, series.stage_grid(reference_stage_), options_, progress);
  FixedSmoothing f;
  f.choice.penalty = r.penalty_deformed;
  f.choice.passes = r.fit_passes;
  f.choice.log10_delta_optimum = r.log10_delta_optimum;
  f.choice.criterion = r.smoothing_criterion == "Cp" ? "Cp" : "GCV";
  f.choice.criterion_value = r.smoothing_criterion_value;
  f.multiplier = r.element_multiplier;
  f.noise = r.noise;
  options_.fixed_smoothing = std::move(f);
  reference_result_ = std::move(r);
}

AnalysisResult SeriesAnalysis::analyse_stage(std::size_t k, const GridData& stage,
                                             const ProgressCallback& progress) const {
  if (options_.method != Method::kSurface) return analyse_triangles(stage, options_);
  if (reference_result_ && k == reference_stage_) return *reference_result_;
  return analyse_deformed(undeformed_, stage, options_, progress);
}

void run_stages(const SeriesAnalysis& analysis,
                const std::function<void(std::size_t k, GridData& grid, AnalysisResult& result)>& take, int ahead) {
  if (ahead <= 0) ahead = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  struct Done {
    GridData grid;
    AnalysisResult result;
  };
  const std::size_t n = analysis.n_stages();
  std::deque<std::future<Done>> flight;
  std::size_t launched = 0;
  auto launch = [&] {
    const std::size_t k = launched++;
    flight.push_back(std::async(std::launch::async, [&analysis, k] {
      Done d;
      d.grid = analysis.stage_grid(k);
      d.result = analysis.analyse_stage(k, d.grid);
      return d;
    }));
  };
  for (std::size_t k = 0; k < n; ++k) {
    while (launched < n && launched <= k + static_cast<std::size_t>(ahead) - 1) launch();
    Done d = flight.front().get();
    flight.pop_front();
    take(k, d.grid, d.result);
  }
}

void StagePrincipalStrains::add(const AnalysisResult& r) {
  const auto n = static_cast<std::size_t>(n_points_);
  std::vector<float> l1(n, std::numeric_limits<float>::quiet_NaN()), l2 = l1;
  for (std::size_t p = 0; p < n && p < r.points.size(); ++p) {
    const auto& s = r.points[p].strain;
    if (!s) continue;
    l1[p] = static_cast<float>(s->lambda1);
    l2[p] = static_cast<float>(s->lambda2);
  }
  lambda1_.push_back(std::move(l1));
  lambda2_.push_back(std::move(l2));
}

std::vector<Index> choose_path_points(const StagePrincipalStrains& strains, const GridData& grid,
                                      const std::vector<std::string>& ids, int count, double min_distance,
                                      const std::string& option) {
  const Index n = grid.n_points();
  std::vector<Index> out;
  if (!ids.empty()) {
    std::unordered_map<std::string, Index> index;
    for (Index p = 0; p < n; ++p) index.emplace(grid.ids[static_cast<std::size_t>(p)], p);
    for (const std::string& id : ids) {
      const auto it = index.find(id);
      if (it == index.end()) throw UsageError(option + ": no point with id '" + id + "' in the series");
      out.push_back(it->second);
    }
    return out;
  }
  if (count <= 0) return out;
  std::vector<double> peak(static_cast<std::size_t>(n), -1.0);
  for (std::size_t k = 0; k < strains.n_stages(); ++k)
    for (Index p = 0; p < n; ++p) {
      const double l1 = strains.lambda1(k, p);
      if (std::isfinite(l1)) peak[static_cast<std::size_t>(p)] = std::max(peak[static_cast<std::size_t>(p)], l1);
    }
  std::vector<Index> order;
  for (Index p = 0; p < n; ++p)
    if (peak[static_cast<std::size_t>(p)] > 0) order.push_back(p);
  std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) {
    return peak[static_cast<std::size_t>(a)] > peak[static_cast<std::size_t>(b)];
  });
  for (const Index p : order) {
    if (static_cast<int>(out.size()) >= count) break;
    const bool far = std::all_of(out.begin(), out.end(), [&](Index q) {
      return !grid.has_undeformed(p) || !grid.has_undeformed(q) ||
             (grid.undeformed.row(p) - grid.undeformed.row(q)).norm() >= min_distance;
    });
    if (far) out.push_back(p);
  }
  return out;
}

std::vector<StrainPath> strain_paths(const StagePrincipalStrains& strains, const GridData& grid,
                                     const std::vector<Index>& points, StrainMeasure measure) {
  std::vector<StrainPath> out;
  for (const Index p : points) {
    StrainPath path;
    path.point = p;
    path.id = grid.ids[static_cast<std::size_t>(p)];
    for (std::size_t k = 0; k < strains.n_stages(); ++k) {
      const double l1 = strains.lambda1(k, p), l2 = strains.lambda2(k, p);
      path.major.push_back(std::isfinite(l1) ? strain_of_stretch(l1, measure) : kNaN);
      path.minor.push_back(std::isfinite(l2) ? strain_of_stretch(l2, measure) : kNaN);
    }
    out.push_back(std::move(path));
  }
  return out;
}

}  // namespace sf::gsa
