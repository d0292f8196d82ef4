#include "gsa/commands.hpp"

#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

#include "common/cli/app.hpp"
#include "common/cli/progress.hpp"
#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/json.hpp"
#include "common/io/csv.hpp"
#include "common/io/grid_file.hpp"
#include "common/render/display.hpp"
#include "gsa/analysis.hpp"
#include "gsa/analysis_checks.hpp"
#include "gsa/batch_command.hpp"
#include "gsa/centring.hpp"
#include "gsa/command_options.hpp"
#include "gsa/compare_command.hpp"
#include "gsa/digitise/commands.hpp"
#include "gsa/grid.hpp"
#include "gsa/gross_blunders.hpp"
#include "gsa/flc.hpp"
#include "gsa/output.hpp"
#include "gsa/option_error.hpp"
#include "gsa/plots.hpp"
#include "gsa/view3d.hpp"
#include "gsa/results_folder.hpp"
#include "gsa/series_output.hpp"
#include "gsa/synthetic.hpp"

namespace sf::gsa {

namespace {

void add_plot_options(CLI::App& app, std::string& measure, std::string& size, std::string& view, std::string& flc) {
  app.add_option("--measure", measure, "Strain measure of the pictures: true (default), engineering or lagrangian");
  app.add_option("--size", size, "Picture size WxH in pixels (default 1200x900)");
  app.add_option("--view", view,
                 "View of the formed part: auto (along its mean normal, default), top, iso, front, side, "
                 "or a direction x,y,z from the part to the eye");
  app.add_option("--flc", flc,
                 "Forming limit curve CSV (columns minor,major, in the --measure strain): drawn in the "
                 "principal strain plot; strains.csv gets flc_margin");
}

// The press-shop options of `gsa analyse` (docs/usage.md "Mid-surface strains",
// "Forming-limit assessment", "Sections").
void add_press_options(CLI::App& app, AnalyseFlags& a) {
  app.add_option("--thickness", a.thickness,
                 "Initial sheet thickness in the length unit (mm): mid-surface strains and the current thickness "
                 "(strains.csv mid_major, mid_minor, thickness_mm); the forming limit is then assessed on them");
  app.add_option("--grid-face", a.grid_face,
                 "Face the grid is on: top (default; the side the fitted surface's normal points to) or bottom");
  app.add_option("--flc-n", a.flc_n,
                 "Forming limit curve from Keeler-Brazier (low-carbon steels) with this strain-hardening exponent n "
                 "(0.05..0.35) and --thickness");
  app.add_option("--flc0", a.flc0,
                 "Forming limit curve from its plane-strain limit FLC0 (in the --measure strain) and the standard "
                 "shape");
  app.add_option("--necking-margin", a.necking_margin,
                 "Necking risk zone: within this strain below the forming limit curve (default 0.10)");
  app.add_option("--thinning-limit", a.thinning_limit,
                 "Excess thinning zone: thinning beyond this many percent (default 30)");
  app.add_option("--min-stretch", a.min_stretch, "Insufficient stretch zone: major strain below this (default 0.02)");
  app.add_option("--section", a.sections,
                 "Section line (repeatable): plane:X,Y,Z,NX,NY,NZ (point and normal, cutting the formed part) or "
                 "curve:X,Y;X,Y;... (points on the undeformed blank); writes section_N.csv and section_N.png")
      ->allow_extra_args(false);
  app.add_flag("--neck", a.neck,
               "Evaluate the neck along each section (ISO 12004-2 style inverse parabola; summary.json, "
               "section_N.csv)");
}

// The grid, from one file or two, with the status lines of reading.
struct Input {
  GridData grid;
  RunInfo info;
  double read_seconds = 0.0;
};
Input read_input(const AnalyseFlags& a, bool quiet) {
  const GridReadOptions ro = grid_read_options(a);
  const auto t0 = std::chrono::steady_clock::now();
  Input in;
  in.info.command_line = cli::command_line().empty() ? "gsa analyse" : cli::command_line();
  if (!a.grid.empty()) {
    if (!a.undeformed.empty() || !a.deformed.empty())
      throw UsageError("give either GRID.csv or --undeformed U.csv --deformed D.csv, not both");
    cli::status(quiet, "gsa: reading " + a.grid);
    in.grid = read_grid(a.grid, ro);
    in.info.inputs = {a.grid};
  } else {
    if (a.undeformed.empty() || a.deformed.empty())
      throw UsageError("give GRID.csv, or both --undeformed U.csv and --deformed D.csv");
    cli::status(quiet, "gsa: reading " + a.undeformed + " and " + a.deformed);
    in.grid = read_grid_pair(a.undeformed, a.deformed, ro);
    in.info.inputs = {a.undeformed, a.deformed};
  }
  in.read_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  for (const std::string& note : in.grid.notes) cli::status(quiet, "gsa: note: " + note);
  return in;
}

// The status line of each stage of the analysis that has one.
ProgressCallback stage_status_lines(bool quiet) {
  return [quiet](const StageStart& s) {
    switch (s.stage) {
      case AnalysisStage::kUndeformedFit:
        cli::status(quiet, "gsa: mesh " + s.mesh->layout + " (" + std::to_string(s.mesh->mesh.n_elements()) +
                               " elements); fitting the undeformed surface");
        break;
      case AnalysisStage::kDeformedFit:
        cli::status(quiet, "gsa: fitting the deformed surface");
        break;
      case AnalysisStage::kSmoothingChoice:
        cli::status(quiet, "gsa: estimating the noise and choosing the smoothing");
        break;
      case AnalysisStage::kOutliers:
        cli::status(quiet, "gsa: checking the marks against their neighbours");
        break;
      case AnalysisStage::kFrameAndMesh:
      case AnalysisStage::kStrains:
        break;
    }
  };
}

// "gsa: 441 of 441 points analysed; results in DIR (mesh 7x7, ...)".
std::string closing_line(const AnalysisResult& result, Index n_points, const std::string& out, const std::string& units,
                         const std::optional<FlcMargins>& margins,
                         const std::optional<FlcAssessment>& assessment = std::nullopt) {
  Index ok = 0;
  for (const auto& p : result.points) ok += p.strain ? 1 : 0;
  std::ostringstream msg;
  msg << "gsa: " << ok << " of " << n_points << " points analysed; results in " << out;
  if (result.method == Method::kSurface)
    msg << " (mesh " << result.mesh_layout << ", " << result.mesh.n_elements() << " elements; fit RMS residual "
        << result.rms_undeformed << " / " << result.rms_deformed << " " << units << "; gauge length "
        << std::setprecision(3) << result.gauge_length << " " << units;
  if (result.method == Method::kSurface && result.relaxed_elements > 0)
    msg << ", " << result.local_gauge_length << " " << units << " in " << result.relaxed_elements
        << " elements with a local feature";
  if (result.method == Method::kSurface) msg << ")";
  Index flagged = 0;
  for (const auto& p : result.points) flagged += p.flag ? 1 : 0;
  if (flagged > 0)
    msg << "; " << flagged << " isolated mark" << (flagged == 1 ? "" : "s")
        << " flagged as outliers, strains kept (see summary.json)";
  if (margins)
    msg << "; " << margins->n_beyond << " of " << margins->n_marks << " marks beyond the forming limit curve";
  if (assessment) {
    msg << " (zones:";
    bool first = true;
    for (const auto& [zone, n] : assessment->counts)
      if (n > 0) msg << (first ? " " : ", ") << n << " " << zone, first = false;
    msg << ")";
  }
  return msg.str();
}

// The progress bar of the pictures (on a terminal, unless quiet).
PictureProgress picture_bar(bool quiet) {
  auto bar = std::make_shared<std::unique_ptr<cli::Progress>>();
  return [bar, quiet](int done, int total) {
    if (!*bar) *bar = std::make_unique<cli::Progress>("gsa: drawing pictures", total, quiet);
    (*bar)->update(done);
    if (done == total) (*bar)->finish();
  };
}

int run_analyse(const AnalyseFlags& a, bool quiet) {
  if (a.out.empty()) throw UsageError("--out: empty; give the folder to write the results into (e.g. --out results)");
  if (!a.stages.empty() || !a.stage_column.empty()) {
    if (a.thickness || a.flc_n || a.flc0 || !a.sections.empty())
      throw UsageError(
          "--thickness, --flc-n, --flc0 and --section are not available with a stage series yet: "
          "analyse the stage of interest on its own");
    return run_analyse_series(a, quiet);  // gsa/series_output.cpp
  }
  const AnalyseOptions options = analyse_options(a);
  OutputOptions output = output_options(a);  // reads the forming limit curve, with or without pictures
  output.keep_surfaces = !a.no_plots;
  PlotOptions po;
  std::shared_ptr<render::DisplayGuard> display;
  if (!a.no_plots) {
    po = plot_options(a.size, a.view);
    display = render::acquire_display();  // no display: fail now, not after the analysis
  }
  // The folder's lock first: a second run into the same folder stops now, not after its analysis.
  io::AtomicOutputDir out(a.out, analyse_results_folder());
  Input in = read_input(a, quiet);
  cli::status(quiet, "gsa: " + std::to_string(in.grid.n_points()) + " points; analysing (" + a.method + " method)");
  // Fit centred coordinates (gsa/centring.hpp); the outputs keep the coordinates given.
  GridData centred = in.grid;
  const Centring centring = centre_grid(centred, !a.mesh.empty(), output.units);
  // Marks typed wrong by far are flagged and left out before any fit (gsa/gross_blunders.hpp).
  const std::vector<GrossBlunder> blunders = screen_gross_blunders(centred);
  AnalysisResult result = analyse(centred, options, stage_status_lines(quiet));
  uncentre(result, centring);
  report_gross_blunders(result, in.grid, blunders, output.units);
  for (std::size_t b = 0; b < blunders.size(); ++b)
    cli::status(quiet, "gsa: warning: " + result.warnings[result.warnings.size() - blunders.size() + b]);
  if (!a.mesh.empty())
    if (const auto w = warn_uncovered_marks(result, a.mesh)) cli::status(quiet, "gsa: warning: " + *w);
  if (!centring.warning.empty()) {
    cli::status(quiet, "gsa: warning: " + centring.warning);
    result.warnings.push_back(centring.warning);
  }
  result.times.read = in.read_seconds;
  refuse_if_nothing_analysed(result, in.grid, a.method);
  cli::status(quiet, "gsa: writing results");
  WrittenResults written = write_results(out, in.grid, result, output, in.info);
  if (!a.no_plots) {
    cli::status(quiet, "gsa: drawing pictures");
    PlotData data = plot_data(result, written.summary, std::move(written.undeformed), std::move(written.deformed),
                              a.out, output.measure);
    data.flc = output.flc;
    data.margins = written.margins;
    data.assessment = written.press.assessment;
    // The principal strain plot shows the strains the zones were assessed on.
    if (!written.press.mid.empty()) data.marks = assessed_strains(result, written.press.mid, output.measure);
    data.sections = written.sections;
    data.section_options.measure = output.measure;
    data.section_options.mid = output.mid;
    write_pictures(
        data, po, [&out](const std::string& name) { return out.path(name); }, picture_bar(quiet));
  }
  out.commit();
  const std::optional<FlcAssessment> assessment = written.press.assessment;
  const std::size_t n_sections = written.sections.size();
  cli::status(quiet, closing_line(result, in.grid.n_points(), a.out, output.units, written.margins, assessment) +
                         (n_sections > 0 ? "; " + std::to_string(n_sections) + " section" +
                                               (n_sections == 1 ? "" : "s") + " (section_N.csv)"
                                         : ""));
  return cli::kExitOk;
}

struct PlotArgs {
  std::string dir, measure = "true", size = "1200x900", view = "auto", flc;
};

int run_plot(const PlotArgs& a, bool quiet) {
  const StrainMeasure measure = parse_measure(a.measure, "--measure");
  const PlotOptions po = plot_options(a.size, a.view);
  std::optional<FormingLimitCurve> flc;
  if (!a.flc.empty()) flc = read_flc(a.flc);  // a bad curve file fails before any work
  if (!std::filesystem::is_directory(a.dir))
    throw InputError(a.dir + ": no such folder; give a results folder written by `gsa analyse`");
  // Another curve or measure: the zones picture of gsa analyse's curve is not carried over.
  io::OutputDirOptions keep;
  const auto summary = std::filesystem::path(a.dir) / "summary.json";
  if (flc && !(std::filesystem::exists(summary) && zones_belong_to(io::read_json(summary.string()), *flc, measure)))
    keep.owned = {"zones.png"};
  io::AtomicOutputDir out(a.dir, keep);
  const Redrawn r = redraw_results_folder(
      a.dir, measure, flc, po, [&out](const std::string& name) { return out.path(name); }, picture_bar(quiet));
  out.commit();
  std::ostringstream msg;
  msg << "gsa: " << r.pictures.pictures.size() << " pictures and report.html in " << a.dir;
  if (r.margins)
    msg << "; " << r.margins->n_beyond << " of " << r.margins->n_marks << " marks beyond the forming limit curve"
        << " (flc_margin in strains.csv)";
  cli::status(quiet, msg.str());
  return cli::kExitOk;
}

struct ViewArgs {
  std::string dir, measure = "true", out;
  View3dOptions options;
};

int run_view(const ViewArgs& a, bool quiet) {
  const StrainMeasure measure = parse_measure(a.measure, "--measure");
  View3dStats st;
  try {
    st = write_view_page(a.dir, measure, a.options, a.out);
  } catch (const OptionError& e) {
    throw UsageError((e.field() == "max_vertices" ? "--max-vertices: " : "--max-mark-values: ") + e.problem());
  }
  std::ostringstream msg;
  msg << "gsa: wrote " << (a.out.empty() ? (std::filesystem::path(a.dir) / "view.html").string() : a.out) << " ("
      << st.triangles << " triangles, " << st.quads_per_element_side << "x" << st.quads_per_element_side
      << " per element, " << st.marks << " marks, " << st.glyph_sites << " arrow sites; "
      << (st.data_bytes + 999) / 1000 << " kB of data)";
  if (!st.mark_columns_left_out.empty())
    msg << "; left out to keep the page small: " << st.mark_columns_left_out.size() << " columns of strains.csv";
  cli::status(quiet, msg.str());
  return cli::kExitOk;
}

struct SynthArgs {
  std::string name, out, exact;
  SyntheticGridOptions grid;
};

int run_synth(const SynthArgs& a, bool quiet) {
  const SyntheticCase& c = synthetic_case(a.name);
  if (a.grid.n < 2 || !(a.grid.spacing > 0) || a.grid.noise < 0 || a.grid.missing_deformed < 0 ||
      a.grid.missing_deformed >= 1)
    throw UsageError("synth: need --n >= 2, --spacing > 0, --noise >= 0, 0 <= --missing < 1");
  std::vector<ExactStrain> exact;
  const GridData g = make_synthetic_grid(c, a.grid, &exact);
  for (const std::string& f : {a.out, a.exact}) {
    const auto parent = std::filesystem::path(f).parent_path();
    if (!f.empty() && !parent.empty()) std::filesystem::create_directories(parent);
  }
  std::ostringstream generated;
  generated << "generated by: gsa synth " << c.name << " --n " << a.grid.n << " --spacing " << a.grid.spacing
            << " --noise " << a.grid.noise << " --missing " << a.grid.missing_deformed << " --outliers "
            << a.grid.outliers << " --seed " << a.grid.seed;
  io::GridWriteOptions wo;
  wo.comments = {"synthetic grid '" + c.name + "': " + c.description, generated.str()};
  wo.units = "mm";
  io::write_grid_file(a.out, g, wo);
  if (!a.exact.empty()) {
    io::write_file_atomic(a.exact, [&](std::ostream& os) {
      os << "# exact strains of synthetic case '" << c.name << "' at each mark (no noise); E = Green-Lagrange\n";
      io::CsvWriter w(os, {"id", "lambda1", "lambda2", "E1", "E2", "shear_angle_deg"});
      for (Index p = 0; p < g.n_points(); ++p) {
        const ExactStrain& e = exact[p];
        w.begin_row()
            .add(g.ids[p])
            .add(e.lambda1)
            .add(e.lambda2)
            .add(0.5 * (e.lambda1 * e.lambda1 - 1))
            .add(0.5 * (e.lambda2 * e.lambda2 - 1))
            .add(e.shear_angle_deg);
        w.end_row();
      }
    });
  }
  cli::status(quiet, "gsa: wrote " + a.out + (a.exact.empty() ? "" : " and " + a.exact));
  return cli::kExitOk;
}

void add_analyse_command(sf::cli::Program& program) {
  const sf::cli::Program* prog = &program;
  auto args = std::make_shared<AnalyseFlags>();
  program.add_command(
      "analyse", "Grid strain analysis of a digitised part (surface fit or classical triangles)",
      [args](CLI::App& app) {
        app.add_option("grid", args->grid,
                       "Grid file (CSV: id,X,Y,Z,x,y,z[,i,j]), or a measuring system's export with --format; - reads "
                       "it from stdin");
        app.add_option("--undeformed", args->undeformed, "Undeformed grid file (id,x,y,z), with --deformed");
        app.add_option("--deformed", args->deformed, "Deformed grid file (id,x,y,z), with --undeformed");
        app.add_option("-o,--out", args->out, "Output folder (created; files replaced only on success)")->required();
        app.add_option("--method", args->method, "surface (default) or triangles (classical, for comparison)");
        app.add_option("--penalty", args->penalty,
                       "Smoothing: jumps (default; fourth order, C3 edge jumps, weight by cross-validation), third "
                       "(third-order + edge jumps) or sobolev (alpha/beta of the brief)");
        app.add_option("--mesh", args->mesh,
                       "Your own mesh (JSON: nodes and elements, see docs/usage.md) instead of the automatic one");
        app.add_option("--elements", args->elements, "Mesh size NxM (default: from the number of marks)");
        app.add_option("--alpha", args->alpha, "First-derivative smoothing weight (default 0)");
        app.add_option("--beta", args->beta,
                       "Second-derivative (curvature) smoothing weight, units^2 (default: automatic)");
        app.add_option("--gamma", args->gamma, "Third-derivative smoothing weight, units^4 (default: automatic)");
        app.add_option("--delta", args->delta,
                       "Fourth-order (edge-jump) smoothing weight, units^6, with --penalty jumps");
        app.add_option("--fibres", args->fibres,
                       "Fibre mode: two fibre angles in degrees from the X axis on the undeformed sheet, e.g. 0,90");
        app.add_option("--units", args->units,
                       "Length unit to read the coordinates in and to write into every output (default mm); columns "
                       "in other units ([m], [in], '# units: m') are converted");
        app.add_option("--format", args->format,
                       "Layout of the input: auto (default: a preset when the header holds its columns and key, "
                       "else plain), plain (the grid file), gom (GOM/ZEISS ARAMIS, Correlate), matchid, vic3d or "
                       "dice (see docs/usage.md, Input formats)");
        app.add_option("--columns", args->columns,
                       "Map column names, e.g. X=x0,Y=y0,Z=z0,u=ux,v=uy,w=uz: X,Y,Z reference and x,y,z current "
                       "positions, u,v,w displacements (any two of the three), id, i, j, sigma");
        app.add_option("--id", args->id,
                       "Columns whose cells together make the id, e.g. x_pic,y_pic; or 'row' (the row number)");
        app.add_option("--positions", args->positions,
                       "reference or current: what the position columns of a --format with displacements hold "
                       "(x = X + u, or X = x - u)");
        app.add_option("--delimiter", args->delimiter,
                       "Field separator: auto (default, found from the header), one character, or "
                       "tab/comma/semicolon/space (runs of blanks)");
        app.add_option("--decimal", args->decimal,
                       "Decimal separator of the numbers: auto (default: comma when the numbers are written so and the "
                       "delimiter is not a comma), point or comma");
        app.add_option("--skip-lines", args->skip_lines,
                       "Skip the first N lines of each file, then look for the header");
        app.add_option("--header-line", args->header_line, "The header is line N of each file (1-based)");
        app.add_option("--pixel-size", args->pixel_size,
                       "Length units per image pixel, for columns in pixels (DICe 2-D positions, VIC-3D/DICe sigma)");
        app.add_option("--pitch", args->pitch,
                       "Grid pitch: undeformed positions from the grid indices, X = j * pitch, Y = i * pitch, Z = 0");
        app.add_option("--smoothing-scale", args->smoothing_scale,
                       "Multiply the automatic smoothing weights (default 1; >1 smoother)");
        app.add_option("--outlier-sigma", args->outlier_sigma,
                       "Flag a mark as an isolated blunder when it is this many noise levels off its neighbours' local "
                       "fit and far more than they are (default 4.5); flagged marks still get a strain");
        app.add_option("--smoothing-rule", args->smoothing_rule,
                       "How the automatic smoothing is chosen: noise-model (default; Cp with the estimated noise, "
                       "spatial correlation included) or gcv (cross-validation, assumes independent errors)");
        app.add_flag("--no-local-smoothing", args->no_local_smoothing,
                     "Keep one smoothing weight and the uniform automatic mesh everywhere (by default the smoothing "
                     "is relaxed, and the mesh refined, where the fit cannot follow a localised feature such as a "
                     "neck)");
        app.add_flag("--no-sigma-weights", args->no_sigma_weights,
                     "Fit every point with weight 1 (by default a point with an uncertainty column, e.g. sigma, "
                     "is weighted 1/sigma^2, normalised to the median sigma)");
        app.add_option("--stages", args->stages,
                       "Stage series: the deformed states, one file per stage, or folders of them (natural order); "
                       "with --undeformed REF as the reference, else each point's reference position in its first "
                       "stage (see docs/usage.md, Stage series)");
        app.add_option("--stage-column", args->stage_column,
                       "Stage series in one GRID file: the column naming each row's stage");
        app.add_option("--reference-stage", args->reference_stage,
                       "With --stage-column: the stage whose positions are the undeformed ones");
        app.add_option("--stage-smoothing", args->stage_smoothing,
                       "Stage series: choose the automatic smoothing once, on the last stage (default), or on each "
                       "stage ('each'; slower)");
        app.add_option("--strain-paths", args->strain_paths,
                       "Stage series: draw the strain paths of the N highest-strain points (default 5; 0: none)");
        app.add_option("--path-ids", args->path_ids,
                       "Stage series: draw the strain paths of these point ids (comma separated) instead");
        app.add_option("--sample", args->sample, "Also write samples.csv with fields on N x N points per element");
        app.add_flag("--no-plots", args->no_plots, "Do not draw pictures (PNG) nor report.html");
        add_plot_options(app, args->measure, args->size, args->view, args->flc);
        add_press_options(app, *args);  // mid-surface, forming-limit assessment, sections (issue 17)
      },
      [args, prog] { return run_analyse(*args, prog->common().quiet); });
}

void add_plot_command(sf::cli::Program& program) {
  const sf::cli::Program* prog = &program;
  auto plot = std::make_shared<PlotArgs>();
  program.add_command(
      "plot", "Redraw the pictures and report.html of a results folder (other measure, size, view, FLC)",
      [plot](CLI::App& app) {
        app.add_option("results", plot->dir, "Results folder written by gsa analyse")->required();
        add_plot_options(app, plot->measure, plot->size, plot->view, plot->flc);
      },
      [plot, prog] { return run_plot(*plot, prog->common().quiet); });
}

void add_view_command(sf::cli::Program& program) {
  const sf::cli::Program* prog = &program;
  auto view = std::make_shared<ViewArgs>();
  program.add_command(
      "view", "Write view.html: the interactive 3-D view of a results folder (opens offline in a browser)",
      [view](CLI::App& app) {
        app.add_option("results", view->dir, "Results folder written by gsa analyse (surface method)")->required();
        app.add_option("-o,--out", view->out, "Page to write (default RESULTS/view.html)");
        app.add_option("--measure", view->measure,
                       "Strain measure of the arrows and the first fields: true, engineering or lagrangian")
            ->default_str("true");
        app.add_option("--max-vertices", view->options.max_vertices,
                       "Surface vertices in the page; above, 4x4, 2x2 or 1x1 quads per element (default 60000)");
        app.add_option("--max-mark-values", view->options.max_mark_values,
                       "Marks x strains.csv columns in the page; above, the least read columns are left out "
                       "(default 1000000)");
      },
      [view, prog] { return run_view(*view, prog->common().quiet); });
}

void add_synth_command(sf::cli::Program& program) {
  const sf::cli::Program* prog = &program;
  auto synth = std::make_shared<SynthArgs>();
  program.add_command(
      "synth", "Write a synthetic grid file from an analytic deformation with exact strains",
      [synth](CLI::App& app) {
        app.add_option("case", synth->name, "rigid, stretch, shear, cylinder, dome, wavy or trellis")->required();
        app.add_option("-o,--out", synth->out, "Grid file to write")->required();
        app.add_option("--exact", synth->exact, "Also write the exact strains per mark to this CSV");
        app.add_option("--n", synth->grid.n, "Marks per side (default 21)");
        app.add_option("--spacing", synth->grid.spacing, "Mark spacing in mm (default 5)");
        app.add_option("--noise", synth->grid.noise, "Digitisation noise, standard deviation per coordinate, mm");
        app.add_option("--missing", synth->grid.missing_deformed, "Fraction of marks without a deformed position");
        app.add_option("--outliers", synth->grid.outliers, "Number of marks digitised 2 mm off");
        app.add_option("--seed", synth->grid.seed, "Random seed (default 1)");
        app.add_flag("--round", synth->grid.round, "A round blank: only the marks inside the inscribed circle");
      },
      [synth, prog] { return run_synth(*synth, prog->common().quiet); });
}

}  // namespace

void register_commands(sf::cli::Program& program) {
  add_analyse_command(program);
  add_plot_command(program);
  add_view_command(program);  // gsa/view3d.hpp (docs/usage.md "3-D view")
  add_synth_command(program);
  add_compare_command(program);          // gsa/compare.hpp
  add_batch_command(program);            // gsa/batch_command.cpp (docs/batch.md)
  digitise::register_commands(program);  // calibrate, digitise, synth-images (docs/digitise.md)
  program.add_command(
      "info", "Print version and build information", [](CLI::App&) {},
      [] {
        std::cout << "gsa " << SF_VERSION << " (grid strain analysis by surface fitting)\n";
        return sf::cli::kExitOk;
      });
}

}  // namespace sf::gsa
