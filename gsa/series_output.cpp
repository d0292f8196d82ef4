#include "gsa/series_output.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>

#include "common/cli/app.hpp"
#include "common/cli/progress.hpp"
#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/csv.hpp"
#include "common/io/json.hpp"
#include "common/io/vtk_xml.hpp"
#include "common/render/display.hpp"
#include "gsa/command_options.hpp"
#include "gsa/plots.hpp"
#include "gsa/series.hpp"

namespace sf::gsa {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

nlohmann::json json_number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

nlohmann::json range_json(double lo, double hi) {
  if (!(lo <= hi)) return nullptr;
  return {{"min", lo}, {"max", hi}};
}

// Stage times when every stage has one and they increase; else nothing (the indices serve).
bool usable_times(const io::GridSeries& s) {
  for (std::size_t k = 0; k < s.n_stages(); ++k) {
    if (!std::isfinite(s.stages[k].time)) return false;
    if (k > 0 && !(s.stages[k].time > s.stages[k - 1].time)) return false;
  }
  return true;
}

// The summary entry of one stage.
nlohmann::json stage_entry(std::size_t k, const io::GridStage& st, const std::string& surface,
                           const AnalysisResult& r) {
  std::map<std::string, Index> counts;
  Index flagged = 0;
  double lo[4], hi[4];
  for (int i = 0; i < 4; ++i) lo[i] = HUGE_VAL, hi[i] = -HUGE_VAL;
  for (const PointResult& p : r.points) {
    ++counts[p.status];
    flagged += p.flag ? 1 : 0;
    if (!p.strain) continue;
    const double v[4] = {p.strain->true_strain(0), p.strain->true_strain(1), p.strain->green(0), p.strain->green(1)};
    for (int i = 0; i < 4; ++i) lo[i] = std::min(lo[i], v[i]), hi[i] = std::max(hi[i], v[i]);
  }
  nlohmann::json e = {{"index", k},
                      {"name", st.name},
                      {"time", json_number(st.time)},
                      {"source", st.source},
                      {"counts", counts},
                      {"flagged_outliers", flagged},
                      {"strain_ranges",
                       {{"true1", range_json(lo[0], hi[0])},
                        {"true2", range_json(lo[1], hi[1])},
                        {"E1", range_json(lo[2], hi[2])},
                        {"E2", range_json(lo[3], hi[3])}}}};
  if (!surface.empty()) e["surface"] = surface;
  if (r.method == Method::kSurface) {
    e["fit"] = {{"rms_residual", r.rms_deformed}, {"max_residual", r.max_deformed}};
    e["smoothing"] = {{"criterion", r.smoothing_criterion.empty() ? nullptr : nlohmann::json(r.smoothing_criterion)},
                      {"log10_delta_optimum", json_number(r.log10_delta_optimum)},
                      {"gauge_length", r.gauge_length},
                      {"relaxed_elements", r.relaxed_elements},
                      {"local_gauge_length", r.relaxed_elements > 0 ? nlohmann::json(r.local_gauge_length) : nullptr}};
    e["noise_deformed_sigma_total"] = r.noise.sigma_total();
    e["sigma_weights"] = r.weights_deformed.used;
    e["rigid_translation"] = {r.rigid.translation[0], r.rigid.translation[1], r.rigid.translation[2]};
  }
  e["timings_s"] = {{"fit", r.times.fit}, {"strain", r.times.strain}, {"write", r.times.write}};
  return e;
}

}  // namespace

std::string stage_surface_name(std::size_t k, std::size_t n_stages) {
  const int digits = std::max(3, static_cast<int>(std::to_string(n_stages > 0 ? n_stages - 1 : 0).size()));
  return fmt::format("stages/stage_{:0{}d}.vtp", k, digits);
}

std::vector<std::string> series_strain_columns() {
  return {"stage",  "stage_name", "time",   "id",       "status",     "E1",
          "E2",     "eng1",       "eng2",   "true1",    "true2",      "thickness_change_pct",
          "dir1_x", "dir1_y",     "dir1_z", "residual", "flag_reason"};
}

struct SeriesWriter::Impl {
  io::AtomicOutputDir* out = nullptr;
  const io::GridSeries* series = nullptr;
  OutputOptions options;
  bool surfaces = true;
  std::ofstream csv_file;
  std::unique_ptr<io::CsvWriter> csv;
  std::string csv_path;
  nlohmann::json stages = nlohmann::json::array();
  std::vector<std::pair<double, std::string>> pvd;
  bool times = false;
};

SeriesWriter::SeriesWriter(io::AtomicOutputDir& out, const io::GridSeries& series, const OutputOptions& options,
                           bool surfaces)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.out = &out;
  s.series = &series;
  s.options = options;
  s.surfaces = surfaces;
  s.times = usable_times(series);
  s.csv_path = out.path("series_strains.csv");
  s.csv_file.open(s.csv_path);
  if (!s.csv_file) throw Error(s.csv_path + ": cannot write");
  s.csv_file << "# gsa stage series: one row per point and stage (" << series.n_stages() << " stages, "
             << series.n_points() << " points); lengths in " << options.units
             << "; strains dimensionless (E = Green-Lagrange, eng = engineering, true = logarithmic); E1 >= E2; "
                "time = the stage's time where its name or stage value gives one; status per stage as in "
                "strains.csv (a point not measured in a stage is flagged there only)\n";
  s.csv = std::make_unique<io::CsvWriter>(s.csv_file, series_strain_columns());
}

SeriesWriter::~SeriesWriter() = default;

void SeriesWriter::add_stage(std::size_t k, const GridData& grid, const AnalysisResult& r) {
  Impl& s = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  const io::GridStage& st = s.series->stages.at(k);
  std::string surface;
  if (s.surfaces && r.method == Method::kSurface) {
    surface = stage_surface_name(k, s.series->n_stages());
    io::write_vtp(s.out->path(surface), surface_polymesh(r, true));
    s.pvd.emplace_back(s.times ? st.time : static_cast<double>(k), surface);
  }
  io::CsvWriter& w = *s.csv;
  for (Index p = 0; p < grid.n_points(); ++p) {
    const PointResult& pr = r.points[static_cast<std::size_t>(p)];
    w.begin_row()
        .add(static_cast<Index>(k))
        .add(st.name)
        .add(st.time)
        .add(grid.ids[static_cast<std::size_t>(p)])
        .add(pr.status);
    if (pr.strain) {
      const SurfaceStrain& e = *pr.strain;
      w.add(e.green(0))
          .add(e.green(1))
          .add(e.engineering(0))
          .add(e.engineering(1))
          .add(e.true_strain(0))
          .add(e.true_strain(1))
          .add(e.thickness_change_pct())
          .add(e.dir1_deformed[0])
          .add(e.dir1_deformed[1])
          .add(e.dir1_deformed[2]);
    } else {
      for (int i = 0; i < 10; ++i) w.add(kNaN);
    }
    w.add(pr.residual).add(pr.flag ? std::string(code(pr.flag->reason)) : std::string());
    w.end_row();
  }
  if (!s.csv_file) throw Error(s.csv_path + ": write failed");
  nlohmann::json e = stage_entry(k, st, surface, r);
  e["timings_s"]["write"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  s.stages.push_back(std::move(e));
}

nlohmann::json SeriesWriter::finish(const std::vector<StrainPath>& paths, double undeformed_seconds,
                                    const std::string& smoothing) {
  Impl& s = *impl_;
  s.csv.reset();
  s.csv_file.close();
  if (!s.csv_file) throw Error(s.csv_path + ": write failed");
  if (!s.pvd.empty()) io::write_pvd(s.out->path("series.pvd"), s.pvd);
  {
    const std::string path = s.out->path("strain_paths.csv");
    std::ofstream f(path);
    if (!f) throw Error(path + ": cannot write");
    const auto names = measure_fields(s.options.measure);
    f << "# gsa strain paths: major and minor " << measure_name(s.options.measure)
      << " strain of the path points at every stage (empty where the point has no strain in that stage)\n";
    io::CsvWriter w(f, {"id", "stage", "stage_name", "time", "major_" + names[0], "minor_" + names[1]});
    for (const StrainPath& p : paths)
      for (std::size_t k = 0; k < p.major.size(); ++k) {
        const io::GridStage& st = s.series->stages[k];
        w.begin_row().add(p.id).add(static_cast<Index>(k)).add(st.name).add(st.time).add(p.major[k]).add(p.minor[k]);
        w.end_row();
      }
    if (!f) throw Error(path + ": write failed");
  }
  nlohmann::json ids = nlohmann::json::array();
  for (const StrainPath& p : paths) ids.push_back(p.id);
  return {
      {"n_stages", s.series->n_stages()},
      {"n_points", s.series->n_points()},
      {"top_level_results", "strains.csv, undeformed.vtp, deformed.vtp and the pictures are those of the last stage"},
      {"outputs",
       {{"table", "series_strains.csv"},
        {"surfaces", s.pvd.empty() ? nullptr : nlohmann::json("series.pvd")},
        {"strain_paths", "strain_paths.csv"}}},
      {"time_axis", s.times ? "stage time (s, from the stage names or values)" : "stage index"},
      {"undeformed_seconds", undeformed_seconds},
      {"smoothing", smoothing},
      {"reuse",
       "one undeformed fit (mesh, material coordinates, penalty matrices, undeformed noise and correlation length) "
       "for every stage; per stage: outlier check, weights, deformed fit, smoothing choice, strains"},
      {"strain_paths", {{"measure", measure_name(s.options.measure)}, {"ids", ids}}},
      {"stages", s.stages}};
}

namespace {

io::GridSeries read_series(const AnalyseFlags& a, RunInfo& info) {
  const GridReadOptions ro = grid_read_options(a);
  if (!a.stages.empty()) {
    if (!a.grid.empty())
      throw UsageError("--stages: give the stage files or folders after --stages, and no GRID file besides");
    if (!a.deformed.empty()) throw UsageError("--stages: the stages are the deformed states; give no --deformed");
    if (!a.stage_column.empty()) throw UsageError("give either --stages or --stage-column, not both");
    io::GridSeries s = io::read_grid_series(a.undeformed, a.stages, ro);
    info.inputs = s.sources;
    return s;
  }
  if (a.grid.empty()) throw UsageError("--stage-column: give the GRID file that holds the column");
  if (!a.undeformed.empty() || !a.deformed.empty())
    throw UsageError("--stage-column: one file holds every stage; give no --undeformed/--deformed");
  io::GridSeries s = io::read_grid_series_column(a.grid, a.stage_column, ro, a.reference_stage);
  info.inputs = {a.grid};
  return s;
}

std::vector<std::string> split_ids(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  if (out.empty()) throw UsageError("--path-ids: expected point ids separated by commas, found '" + text + "'");
  return out;
}

}  // namespace

int run_analyse_series(const AnalyseFlags& a, bool quiet) {
  const AnalyseOptions options = analyse_options(a);
  OutputOptions output = output_options(a);
  output.keep_surfaces = !a.no_plots;
  if (!a.reference_stage.empty() && a.stage_column.empty())
    throw UsageError("--reference-stage: applies with --stage-column");
  if (a.strain_paths < 0) throw UsageError("--strain-paths: must be >= 0, found " + std::to_string(a.strain_paths));
  const std::vector<std::string> path_ids = a.path_ids.empty() ? std::vector<std::string>() : split_ids(a.path_ids);
  PlotOptions po;
  std::shared_ptr<render::DisplayGuard> display;
  if (!a.no_plots) {
    po = plot_options(a.size, a.view);
    display = render::acquire_display();
  }
  RunInfo info;
  info.command_line = cli::command_line().empty() ? "gsa analyse" : cli::command_line();
  const auto t_read = std::chrono::steady_clock::now();
  cli::status(quiet, "gsa: reading the stage series");
  const io::GridSeries series = read_series(a, info);
  check_series(series);
  const double read_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_read).count();
  for (const std::string& note : series.notes) cli::status(quiet, "gsa: note: " + note);
  const std::size_t n = series.n_stages();
  cli::status(quiet, fmt::format("gsa: {} points, {} stages; fitting the undeformed surface once ({} method)",
                                 series.n_points(), n, a.method));
  SeriesSmoothing smoothing = SeriesSmoothing::kOnce;
  if (a.stage_smoothing == "each")
    smoothing = SeriesSmoothing::kEachStage;
  else if (a.stage_smoothing != "once")
    throw UsageError("--stage-smoothing: expected 'once' or 'each', found '" + a.stage_smoothing + "'");
  const SeriesAnalysis analysis(series, options, smoothing);
  if (analysis.fixed_smoothing())
    cli::status(quiet, fmt::format("gsa: smoothing chosen on the last stage ({}), gauge length {:.3g} {}, for every "
                                   "stage (--stage-smoothing each: per stage)",
                                   series.stages.back().name,
                                   gauge_length(analysis.fixed_smoothing()->choice.penalty,
                                                analysis.undeformed().setup.mark_spacing),
                                   output.units));
  io::AtomicOutputDir out(a.out, analyse_results_folder());
  SeriesWriter writer(out, series, output, true);
  StagePrincipalStrains principal(series.n_points());
  GridData last_grid;
  AnalysisResult last;
  run_stages(analysis, [&](std::size_t k, GridData& g, AnalysisResult& r) {
    writer.add_stage(k, g, r);
    principal.add(r);
    Index ok = 0, missing = 0;
    double peak = -HUGE_VAL;
    for (const PointResult& p : r.points) {
      if (p.strain) ++ok, peak = std::max(peak, p.strain->true_strain(0));
      if (p.status == kStatusMissingDeformed || p.status == kStatusNotMeasured) ++missing;
    }
    std::string line =
        fmt::format("gsa: stage {}/{} {}: {} of {} points analysed", k + 1, n, series.stages[k].name, ok, g.n_points());
    if (missing > 0) line += fmt::format(" ({} not measured in this stage)", missing);
    if (ok > 0) line += fmt::format(", major true strain up to {:.4g}", peak);
    if (r.method == Method::kSurface) line += fmt::format(", gauge length {:.3g} {}", r.gauge_length, output.units);
    cli::status(quiet, line);
    if (k + 1 == n) {
      last_grid = std::move(g);
      last = std::move(r);
    }
  });
  const double spacing = options.method == Method::kSurface ? analysis.undeformed().setup.mark_spacing : 0.0;
  const std::vector<Index> points =
      choose_path_points(principal, last_grid, path_ids, a.strain_paths, 2.0 * spacing, "--path-ids");
  const std::vector<StrainPath> paths = strain_paths(principal, last_grid, points, output.measure);
  nlohmann::json series_json =
      writer.finish(paths, analysis.undeformed_seconds(),
                    analysis.fixed_smoothing() ? "chosen once, on the last stage (" + series.stages.back().name +
                                                     "), with its local relaxation, for every stage"
                    : options.smoothing.chooses_by_gcv() ? "chosen on each stage"
                                                         : "explicit weights");
  cli::status(quiet, "gsa: writing the results of the last stage");
  last.times.read = read_seconds;
  WrittenResults written = write_results(out, last_grid, last, output, info);
  written.summary["series"] = std::move(series_json);
  io::write_json(out.path("summary.json"), written.summary);
  if (!a.no_plots) {
    cli::status(quiet, "gsa: drawing pictures of the last stage");
    PlotData data = plot_data(last, written.summary, std::move(written.undeformed), std::move(written.deformed), a.out,
                              output.measure);
    data.flc = output.flc;
    data.margins = written.margins;
    data.strain_paths = paths;
    write_pictures(data, po, [&out](const std::string& name) { return out.path(name); });
  }
  out.commit();
  cli::status(quiet, fmt::format("gsa: {} stages of {} points analysed; results in {} (series_strains.csv, "
                                 "series.pvd, strain_paths.csv; strains.csv and pictures: the last stage)",
                                 n, series.n_points(), a.out));
  return cli::kExitOk;
}

}  // namespace sf::gsa
