#include "gsa/commands.hpp"

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <limits>
#include <iostream>
#include <optional>
#include <iomanip>
#include <sstream>

#include "common/cli/app.hpp"
#include "common/cli/progress.hpp"
#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/render/display.hpp"
#include "gsa/analysis.hpp"
#include "gsa/digitise/commands.hpp"
#include "gsa/grid.hpp"
#include "gsa/output.hpp"
#include "gsa/plots.hpp"
#include "gsa/synthetic.hpp"
#include "common/io/csv.hpp"
#include <filesystem>
#include <fstream>

namespace sf::gsa {

namespace {

constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

struct AnalyseArgs {
  std::string grid, undeformed, deformed, out, method = "surface", penalty = "jumps", elements, mesh, columns,
      delimiter = ",", fibres, units = "mm";
  double alpha = kUnset, beta = kUnset, gamma = kUnset, delta = kUnset, outlier_sigma = 6.0, smoothing_scale = 1.0;
  int sample = 0;
  bool no_plots = false;
  std::string measure = "true", size = "1200x900", view = "auto", flc;
  std::string command_line;
};

// Picture options shared by `analyse` and `plot`; usage errors name the option.
PlotOptions make_plot_options(const std::string& measure, const std::string& size, const std::string& view,
                              const std::string& flc, bool quiet) {
  PlotOptions po;
  po.measure = parse_measure(measure, "--measure");
  po.size = render::parse_size(size, "--size");
  po.view = render::parse_view(view, "--view");
  po.flc_path = flc;
  po.quiet = quiet;
  if (!flc.empty()) read_flc(flc);  // bad curve files fail before any work
  return po;
}

void add_plot_options(CLI::App& app, std::string& measure, std::string& size, std::string& view,
                      std::string& flc) {
  app.add_option("--measure", measure, "Strain measure of the pictures: true (default), engineering or lagrangian");
  app.add_option("--size", size, "Picture size WxH in pixels (default 1200x900)");
  app.add_option("--view", view,
                 "View of the formed part: auto (along its mean normal, default), top, iso, front, side, "
                 "or a direction x,y,z from the part to the eye");
  app.add_option("--flc", flc,
                 "Forming limit curve CSV (columns minor,major, in the --measure strain): drawn in the "
                 "principal strain plot; strains.csv gets flc_margin");
}

std::vector<double> parse_angles(const std::string& text) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      std::size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError("--fibres: expected angles in degrees separated by commas (e.g. 0,90), found '" + item + "'");
    }
  }
  return out;
}

int run_analyse(const AnalyseArgs& a, bool quiet) {
  AnalyseOptions o;
  if (a.method == "surface") o.method = Method::kSurface;
  else if (a.method == "triangles") o.method = Method::kTriangles;
  else throw UsageError("--method: expected 'surface' or 'triangles', found '" + a.method + "'");
  if (a.penalty == "third") o.penalty = PenaltyKind::kThirdOrder;
  else if (a.penalty == "sobolev") o.penalty = PenaltyKind::kSobolev;
  else if (a.penalty == "jumps") o.penalty = PenaltyKind::kJumps;
  else throw UsageError("--penalty: expected 'third', 'jumps' or 'sobolev', found '" + a.penalty + "'");
  if (!a.mesh.empty() && !a.elements.empty()) throw UsageError("give either --mesh or --elements, not both");
  o.mesh_file = a.mesh;
  if (!a.elements.empty()) {
    const auto x = a.elements.find('x');
    try {
      if (x == std::string::npos) throw std::invalid_argument("x");
      o.elements1 = std::stoi(a.elements.substr(0, x));
      o.elements2 = std::stoi(a.elements.substr(x + 1));
    } catch (const std::exception&) {
      throw UsageError("--elements: expected NxM (e.g. 8x6), found '" + a.elements + "'");
    }
    if (o.elements1 < 1 || o.elements2 < 1) throw UsageError("--elements: counts must be >= 1");
  }
  const std::pair<const char*, double> weights[] = {
      {"--alpha", a.alpha}, {"--beta", a.beta}, {"--gamma", a.gamma}, {"--delta", a.delta}};
  for (const auto& [name, value] : weights)
    if (!std::isnan(value) && !(value >= 0.0))
      throw UsageError(std::string(name) + ": a smoothing weight must be >= 0, found " + std::to_string(value));
  if (!std::isnan(a.alpha)) o.alpha = a.alpha;
  if (!std::isnan(a.beta)) o.beta = a.beta;
  if (!std::isnan(a.gamma)) o.gamma = a.gamma;
  if (!std::isnan(a.delta)) o.delta = a.delta;
  if (!a.fibres.empty()) o.fibre_angles = parse_angles(a.fibres);
  o.units = a.units;
  o.outlier_sigma = a.outlier_sigma;
  o.smoothing_scale = a.smoothing_scale;
  o.sample = a.sample;
  o.quiet = quiet;
  o.validate();
  PlotOptions po;
  std::shared_ptr<render::DisplayGuard> display;
  if (!a.no_plots) {
    po = make_plot_options(a.measure, a.size, a.view, a.flc, quiet);
    display = render::acquire_display();  // no display: fail now, not after the analysis
  }

  GridReadOptions ro;
  ro.delimiter = parse_delimiter(a.delimiter);
  if (!a.columns.empty()) ro.columns = parse_column_map(a.columns);
  const auto t0 = std::chrono::steady_clock::now();
  GridData grid;
  RunInfo info;
  info.command_line = a.command_line;
  if (!a.grid.empty()) {
    if (!a.undeformed.empty() || !a.deformed.empty())
      throw UsageError("give either GRID.csv or --undeformed U.csv --deformed D.csv, not both");
    cli::status(quiet, "gsa: reading " + a.grid);
    grid = read_grid(a.grid, ro);
    info.inputs = {a.grid};
  } else {
    if (a.undeformed.empty() || a.deformed.empty())
      throw UsageError("give GRID.csv, or both --undeformed U.csv and --deformed D.csv");
    cli::status(quiet, "gsa: reading " + a.undeformed + " and " + a.deformed);
    grid = read_grid_pair(a.undeformed, a.deformed, ro);
    info.inputs = {a.undeformed, a.deformed};
  }
  const double read_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  cli::status(quiet, "gsa: " + std::to_string(grid.n_points()) + " points; analysing (" + a.method + " method)");
  AnalysisResult result = analyse(grid, o);
  result.times.read = read_s;
  io::AtomicOutputDir out(a.out);
  cli::status(quiet, "gsa: writing results");
  write_results(out, grid, result, o, info);
  std::optional<PlotSummary> plots;
  if (!a.no_plots) {
    cli::status(quiet, "gsa: drawing pictures");
    plots = write_pictures(out.temp_dir().string(), [&out](const std::string& name) { return out.path(name); }, po);
  }
  out.commit();
  Index ok = 0;
  for (const auto& p : result.points) ok += p.strain ? 1 : 0;
  std::ostringstream msg;
  msg << "gsa: " << ok << " of " << grid.n_points() << " points analysed; results in " << a.out;
  if (result.method == Method::kSurface)
    msg << " (mesh " << result.mesh_layout << ", " << result.mesh.n_elements()
        << " elements; fit RMS residual " << result.rms_undeformed << " / " << result.rms_deformed << " " << o.units
        << "; gauge length " << std::setprecision(3) << result.gauge_length << " " << o.units << ")";
  if (plots && plots->flc)
    msg << "; " << plots->n_beyond_flc << " of " << plots->n_marks << " marks beyond the forming limit curve";
  cli::status(quiet, msg.str());
  return cli::kExitOk;
}

struct PlotArgs {
  std::string dir, measure = "true", size = "1200x900", view = "auto", flc;
};

int run_plot(const PlotArgs& a, bool quiet) {
  const PlotOptions po = make_plot_options(a.measure, a.size, a.view, a.flc, quiet);
  if (!std::filesystem::is_directory(a.dir))
    throw InputError(a.dir + ": no such folder; give a results folder written by `gsa analyse`");
  io::AtomicOutputDir out(a.dir);
  const PlotSummary s = write_pictures(a.dir, [&out](const std::string& name) { return out.path(name); }, po);
  out.commit();
  std::ostringstream msg;
  msg << "gsa: " << s.pictures.size() << " pictures and report.html in " << a.dir;
  if (s.flc)
    msg << "; " << s.n_beyond_flc << " of " << s.n_marks << " marks beyond the forming limit curve"
        << " (flc_margin in strains.csv)";
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
  io::write_file_atomic(a.out, [&](std::ostream& os) {
    os << "# synthetic grid '" << c.name << "': " << c.description << "\n";
    os << "# generated by: gsa synth " << c.name << " --n " << a.grid.n << " --spacing " << a.grid.spacing
       << " --noise " << a.grid.noise << " --missing " << a.grid.missing_deformed << " --outliers "
       << a.grid.outliers << " --seed " << a.grid.seed << "\n# units: mm\n";
    io::CsvWriter w(os, {"id", "X", "Y", "Z", "x", "y", "z", "i", "j"});
    for (Index p = 0; p < g.n_points(); ++p) {
      w.begin_row().add(g.ids[p]);
      for (int k = 0; k < 3; ++k) w.add(g.undeformed(p, k));
      for (int k = 0; k < 3; ++k) w.add(g.deformed(p, k));
      w.add(g.i[p]).add(g.j[p]);
      w.end_row();
    }
  });
  if (!a.exact.empty()) {
    io::write_file_atomic(a.exact, [&](std::ostream& os) {
      os << "# exact strains of synthetic case '" << c.name << "' at each mark (no noise); E = Green-Lagrange\n";
      io::CsvWriter w(os, {"id", "lambda1", "lambda2", "E1", "E2", "shear_angle_deg"});
      for (Index p = 0; p < g.n_points(); ++p) {
        const ExactStrain& e = exact[p];
        w.begin_row().add(g.ids[p]).add(e.lambda1).add(e.lambda2).add(0.5 * (e.lambda1 * e.lambda1 - 1))
            .add(0.5 * (e.lambda2 * e.lambda2 - 1)).add(e.shear_angle_deg);
        w.end_row();
      }
    });
  }
  cli::status(quiet, "gsa: wrote " + a.out + (a.exact.empty() ? "" : " and " + a.exact));
  return cli::kExitOk;
}

}  // namespace

void register_commands(sf::cli::Program& program) {
  auto args = std::make_shared<AnalyseArgs>();
  const sf::cli::Program* prog = &program;
  program.add_command(
      "analyse", "Grid strain analysis of a digitised part (surface fit or classical triangles)",
      [args](CLI::App& app) {
        app.add_option("grid", args->grid, "Grid file (CSV: id,X,Y,Z,x,y,z[,i,j]); - reads it from stdin");
        app.add_option("--undeformed", args->undeformed, "Undeformed grid file (id,x,y,z), with --deformed");
        app.add_option("--deformed", args->deformed, "Deformed grid file (id,x,y,z), with --undeformed");
        app.add_option("-o,--out", args->out, "Output folder (created; files replaced only on success)")->required();
        app.add_option("--method", args->method, "surface (default) or triangles (classical, for comparison)");
        app.add_option("--penalty", args->penalty, "Smoothing: jumps (default; fourth order, C3 edge jumps, weight by cross-validation), third (third-order + edge jumps) or sobolev (alpha/beta of the brief)");
        app.add_option("--mesh", args->mesh, "Your own mesh (JSON: nodes and elements, see docs/usage.md) instead of the automatic one");
        app.add_option("--elements", args->elements, "Mesh size NxM (default: from the number of marks)");
        app.add_option("--alpha", args->alpha, "First-derivative smoothing weight (default 0)");
        app.add_option("--beta", args->beta, "Second-derivative (curvature) smoothing weight, units^2 (default: automatic)");
        app.add_option("--gamma", args->gamma, "Third-derivative smoothing weight, units^4 (default: automatic)");
        app.add_option("--delta", args->delta, "Fourth-order (edge-jump) smoothing weight, units^6, with --penalty jumps");
        app.add_option("--fibres", args->fibres, "Fibre mode: two fibre angles in degrees from the X axis on the undeformed sheet, e.g. 0,90");
        app.add_option("--units", args->units, "Length unit of the coordinates, written into every output (default mm)");
        app.add_option("--columns", args->columns, "Map column names, e.g. X=x0,Y=y0,Z=z0,u=u,v=v,w=w (u,v,w = displacements)");
        app.add_option("--delimiter", args->delimiter, "Field separator: one character, or tab/comma/semicolon/space");
        app.add_option("--smoothing-scale", args->smoothing_scale, "Multiply the automatic smoothing weights (default 1; >1 smoother)");
        app.add_option("--outlier-sigma", args->outlier_sigma, "Flag marks whose fit residual exceeds this many robust noise sigmas (default 6)");
        app.add_option("--sample", args->sample, "Also write samples.csv with fields on N x N points per element");
        app.add_flag("--no-plots", args->no_plots, "Do not draw pictures (PNG) nor report.html");
        add_plot_options(app, args->measure, args->size, args->view, args->flc);
      },
      [args, prog] {
        args->command_line = "gsa analyse";
        return run_analyse(*args, prog->common().quiet);
      });
  auto plot = std::make_shared<PlotArgs>();
  program.add_command(
      "plot", "Redraw the pictures and report.html of a results folder (other measure, size, view, FLC)",
      [plot](CLI::App& app) {
        app.add_option("results", plot->dir, "Results folder written by gsa analyse")->required();
        add_plot_options(app, plot->measure, plot->size, plot->view, plot->flc);
      },
      [plot, prog] { return run_plot(*plot, prog->common().quiet); });
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
  digitise::register_commands(program);  // calibrate, digitise, synth-images (docs/digitise.md)
  program.add_command(
      "info", "Print version and build information", [](CLI::App&) {},
      [] {
        std::cout << "gsa " << SF_VERSION << " (grid strain analysis by surface fitting)\n";
        return sf::cli::kExitOk;
      });
}

}  // namespace sf::gsa
