#include "forming/commands.hpp"

#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>

#include "common/cli/app.hpp"
#include "common/cli/progress.hpp"
#include "forming/case/reader.hpp"
#include "forming/plot/plots.hpp"
#include "forming/run/run.hpp"
#include "forming/stability/command.hpp"

namespace sf::forming {
namespace {

// simform check CASE: every problem with its place, exit 1 if any.
int run_check(const std::string& path, bool quiet) {
  const CaseCheck c = check_case_file(path);
  if (!c.ok()) {
    for (std::size_t i = 0; i < c.problems.size(); ++i) std::cerr << c.located(i) << "\n";
    std::cerr << "simform: " << c.problems.size() << (c.problems.size() == 1 ? " problem" : " problems") << " in "
              << path << "\n";
    return sf::cli::kExitFailure;
  }
  const FormingCase& s = c.spec;
  std::size_t n_elements = 0;
  for (const CasePly& p : s.plies) n_elements += static_cast<std::size_t>(p.n1) * static_cast<std::size_t>(p.n2);
  if (!quiet)
    std::cout << path << ": ok (" << s.plies.size() << (s.plies.size() == 1 ? " ply, " : " plies, ") << n_elements
              << " elements, " << s.materials.size() << (s.materials.size() == 1 ? " material, " : " materials, ")
              << s.boundaries.size() << " boundary conditions, " << s.solver.steps << " load steps)\n";
  return sf::cli::kExitOk;
}

struct RunArgs {
  std::string case_file;
  RunOptions options;
  bool no_plots = false;
};

// The pictures and report.html of a results folder (forming/plot/plots.hpp).
void print_plot_report(const std::string& dir, const PlotReport& r, bool quiet) {
  sf::cli::status(quiet, "simform: wrote " + std::to_string(r.pictures.size()) + " pictures in " + dir + "/plots and " +
                             dir + "/report.html" + (r.animation.empty() ? "" : " (animation " + r.animation + ")"));
  for (const std::string& n : r.notes) sf::cli::status(quiet, "simform: " + n);
}

struct PlotArgs {
  std::string dir;
  std::string size = "1200x900";
  PlotOptions options;
  bool no_animation = false;
};

int run_plot(PlotArgs& a, bool quiet) {
  a.options.size = render::parse_size(a.size, "--size");
  a.options.animation = !a.no_animation;
  a.options.quiet = quiet;
  print_plot_report(a.dir, plot_results(a.dir, a.options), quiet);
  return sf::cli::kExitOk;
}

int run_run(RunArgs& a, bool quiet) {
  a.options.quiet = quiet;
  a.options.command_line = "simform run " + a.case_file + " --out " + a.options.out_dir;
  a.options.validate();
  const FormingCase spec = load_case(a.case_file);
  sf::cli::status(quiet, "simform: running " + a.case_file + " (" + std::to_string(spec.solver.steps) +
                             " load steps) into " + a.options.out_dir);
  const RunReport r = run_case(spec, a.options);
  if (!r.ok()) {
    std::cerr << "simform: error: " << a.case_file << ": " << r.message << " (" << a.options.out_dir
              << "/summary.json has status not_converged)\n";
    return sf::cli::kExitFailure;
  }
  sf::cli::status(quiet, "simform: " + r.brief() + "; wrote " + a.options.out_dir +
                             (a.options.grid_out.empty() ? "" : " and " + a.options.grid_out));
  if (!a.no_plots) {
    // The run's results are complete without pictures: a failure here is a warning.
    try {
      PlotOptions po;  // cheap at the end of a run: 5 frames (simform plot draws 10)
      po.quiet = quiet;
      po.frames = 5;
      print_plot_report(a.options.out_dir, plot_results(a.options.out_dir, po), quiet);
    } catch (const std::exception& e) {
      std::cerr << "simform: warning: no pictures (" << e.what() << "); the results are complete, draw them later "
                << "with 'simform plot " << a.options.out_dir << "'\n";
    }
  }
  return sf::cli::kExitOk;
}

}  // namespace

void register_commands(sf::cli::Program& program) {
  const sf::cli::Program* prog = &program;
  program.add_command(
      "info", "Print version and build information", [](CLI::App&) {},
      [] {
        std::cout << "simform " << SF_VERSION << " (forming solver for fibre-reinforced plies)\n";
        return sf::cli::kExitOk;
      });

  auto check_file = std::make_shared<std::string>();
  program.add_command(
      "check", "Validate a case file and list every problem with its place (file:line:column)",
      [check_file](CLI::App& app) {
        app.add_option("case", *check_file, "Case file (YAML, see docs/forming.md)")->required();
      },
      [check_file, prog] { return run_check(*check_file, prog->common().quiet); });

  auto args = std::make_shared<RunArgs>();
  program.add_command(
      "run", "Run a quasi-static case; write a ParaView series, history.csv and summary.json",
      [args](CLI::App& app) {
        app.add_option("case", args->case_file, "Case file (YAML, see docs/forming.md)")->required();
        app.add_option("-o,--out", args->options.out_dir, "Output folder (files replaced only when written completely)")
            ->required();
        app.add_option("--grid-out", args->options.grid_out,
                       "Also write the final positions of a grid of marks on a ply's top face (gsa grid file)");
        app.add_option("--grid-marks", args->options.grid_marks, "Marks per side of that grid (default 21)")
            ->check(CLI::Range(2, 10000));
        app.add_option("--grid-ply", args->options.grid_ply, "Ply carrying the grid (default: the first)");
        app.add_flag("--restart", args->options.restart,
                     "Continue from the last written step (OUT/restart.json, written with every frame)");
        app.add_option("--stop-after", args->options.stop_after,
                       "Stop cleanly after this many steps (status 'stopped'; continue with --restart)")
            ->check(CLI::NonNegativeNumber);
        app.add_flag("--no-plots", args->no_plots, "Do not draw the pictures and report.html at the end");
      },
      [args, prog] { return run_run(*args, prog->common().quiet); });

  auto plot = std::make_shared<PlotArgs>();
  program.add_command(
      "plot", "Draw the pictures of a results folder (PNG, no display needed) and its report.html",
      [plot](CLI::App& app) {
        app.add_option("results", plot->dir, "Results folder of simform run")->required();
        app.add_option("--ply", plot->options.ply, "Ply whose fibre directions are drawn (default: the top one)");
        app.add_option("--size", plot->size, "Picture size WxH in pixels (default 1200x900)");
        app.add_option("--frames", plot->options.frames, "Frames in the forming sequence (default 10; 0: none)")
            ->check(CLI::Range(0, 1000));
        app.add_flag("--no-animation", plot->no_animation, "Do not write plots/forming.avi");
        app.add_option("--section", plot->options.section_angle_deg,
                       "3-D parts: plan angle (deg from x) of the vertical section through the part centre "
                       "(default 0)")
            ->check(CLI::Range(-180.0, 180.0));
      },
      [plot, prog] { return run_plot(*plot, prog->common().quiet); });

  stability::add_stability_command(program);
}

}  // namespace sf::forming
