// Times a stage series in `gsa analyse` (gsa/series.hpp): one undeformed fit, then a
// deformed fit per stage, on the synthetic bulging stretch of gsa/synthetic_series.hpp
// (default 40 stages of 100 x 100 = 1e4 marks 1 mm apart, noise 0.005 mm per coordinate,
// 2 % of the marks not measured in each stage), and prints the per-stage split (fit,
// strains, writing series_strains.csv rows and stage_NNN.vtp), the total (target: under
// 10 s on 2 cores, no pictures) and the RMS Green-strain error of each stage against the
// exact strains (interior marks). A program that prints figures, not a timed test.
// Smoothing chosen once on the last stage (default) or on each stage ("each").
//   build/bin/gsa_series_bench [stages=40] [marks_per_side=100] [noise=0.005] [once|each]
#include <chrono>
#include <ctime>
#include <string>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "common/io/atomic_file.hpp"
#include "gsa/accuracy.hpp"
#include "gsa/series.hpp"
#include "gsa/series_output.hpp"
#include "gsa/synthetic_series.hpp"

using namespace sf;
using namespace sf::gsa;

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

int main(int argc, char** argv) {
  SyntheticSeriesOptions so;
  so.stages = argc > 1 ? std::atoi(argv[1]) : 40;
  so.n = argc > 2 ? std::atoi(argv[2]) : 100;
  so.noise = argc > 3 ? std::atof(argv[3]) : 0.005;
  so.spacing = 1.0;
  so.stretch = 0.3;
  so.contraction = 0.1;
  so.bulge = 0.1 * so.n * so.spacing;
  so.not_measured = 0.02;
  const SyntheticSeries syn = make_synthetic_series(so);
  const io::GridSeries& series = syn.series;
  std::printf(
      "gsa_series_bench: %zu stages of %ld marks (%d x %d, 1 mm apart), noise %.3g mm, 2 %% not measured "
      "per stage\n",
      series.n_stages(), static_cast<long>(series.n_points()), so.n, so.n, so.noise);
  const auto tmp = std::filesystem::temp_directory_path() / "gsa_series_bench";
  std::filesystem::remove_all(tmp);
  const auto t_all = Clock::now();
  const auto t0 = Clock::now();
  const bool each = argc > 4 && std::string(argv[4]) == "each";
  const std::clock_t c0 = std::clock();
  const SeriesAnalysis analysis(series, AnalyseOptions{}, each ? SeriesSmoothing::kEachStage : SeriesSmoothing::kOnce);
  const double undeformed_s = since(t0);
  std::printf("smoothing chosen %s; undeformed stages%s: %.3f s (mesh %s, %ld elements)\n",
              each ? "on each stage" : "once, on the last stage", each ? "" : " and the last stage in full",
              undeformed_s, analysis.undeformed().setup.layout.c_str(),
              static_cast<long>(analysis.undeformed().setup.mesh.n_elements()));
  std::printf("%6s %8s %8s %8s %8s %10s %10s %9s\n", "stage", "fit_s", "strain_s", "write_s", "wall_s", "rms_err",
              "max_E1", "gauge_mm");
  double sum_fit = 0, sum_strain = 0, sum_write = 0, worst = 0;
  {
    io::AtomicOutputDir out(tmp.string());
    SeriesWriter writer(out, series, OutputOptions{}, true);
    StagePrincipalStrains principal(series.n_points());
    // Stages analysed two at a time ahead while this thread writes (run_stages): the
    // per-stage split below is each stage's own time, the total is the wall time.
    auto ts = Clock::now();
    run_stages(analysis, [&](std::size_t k, GridData& g, AnalysisResult& r) {
      const auto tw = Clock::now();
      writer.add_stage(k, g, r);
      principal.add(r);
      const double write_s = since(tw), stage_s = since(ts);
      ts = Clock::now();
      const StrainError e = strain_error(g, r, syn.exact[k]);
      double max_e1 = 0;
      for (const auto& ex : syn.exact[k]) max_e1 = std::max(max_e1, 0.5 * (ex.lambda1 * ex.lambda1 - 1));
      std::printf("%6zu %8.3f %8.3f %8.3f %8.3f %10.2e %10.4f %9.3f\n", k + 1, r.times.fit, r.times.strain, write_s,
                  stage_s, e.rms(), max_e1, r.gauge_length);
      std::fflush(stdout);
      sum_fit += r.times.fit;
      sum_strain += r.times.strain;
      sum_write += write_s;
      worst = std::max(worst, e.rms());
    });
    const auto tf = Clock::now();
    const std::vector<Index> pts = choose_path_points(principal, analysis.stage_grid(0), {}, 5, 2.0, "paths");
    writer.finish(strain_paths(principal, analysis.stage_grid(0), pts, StrainMeasure::kTrue), undeformed_s);
    out.commit();
    sum_write += since(tf);
  }
  const double total = since(t_all);
  const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  const double n = static_cast<double>(series.n_stages());
  std::printf("per stage (mean, each on its own thread): fit %.3f s, strain %.3f s, write %.3f s\n", sum_fit / n,
              sum_strain / n, sum_write / n);
  std::printf(
      "total %.2f s wall, %.2f s CPU (all threads) for %zu stages (undeformed %.2f s, stages %.2f s); worst "
      "stage RMS error %.2e\n",
      total, cpu, series.n_stages(), undeformed_s, total - undeformed_s, worst);
  std::filesystem::remove_all(tmp);
  return 0;
}
