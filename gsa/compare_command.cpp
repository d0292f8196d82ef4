// `gsa compare MEASURED SIMULATED --out DIR` (gsa/compare.hpp; docs/usage.md, "Comparing two
// analyses"): the command layer.

#include <CLI/CLI.hpp>

#include <chrono>
#include <iomanip>
#include <filesystem>
#include <memory>
#include <sstream>

#include "common/cli/app.hpp"
#include "common/cli/progress.hpp"
#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/json.hpp"
#include "common/render/display.hpp"
#include "gsa/command_options.hpp"
#include "gsa/compare.hpp"
#include "gsa/compare_command.hpp"
#include "gsa/compare_plots.hpp"

namespace sf::gsa {

namespace {

struct CompareArgs {
  std::string measured, simulated, out;
  std::string measure = "true", registration = "auto", blank = "auto", fibres, units = "mm";
  std::string size = "1200x900", view = "auto";
  bool no_plots = false;
};

RegistrationMode parse_registration(const std::string& t) {
  if (t == "auto") return RegistrationMode::kAuto;
  if (t == "ids") return RegistrationMode::kIds;
  if (t == "surface" || t == "icp") return RegistrationMode::kSurface;
  if (t == "none") return RegistrationMode::kNone;
  throw UsageError("--register: expected auto, ids, surface or none, found '" + t + "'");
}

BlankMap parse_blank(const std::string& t) {
  if (t == "auto") return BlankMap::kAuto;
  if (t == "fit") return BlankMap::kFit;
  if (t == "same") return BlankMap::kSame;
  throw UsageError("--blank: expected auto, fit or same, found '" + t + "'");
}

// A results folder, or a grid file analysed now.
CompareSide load_side(const std::string& path, const CompareArgs& a, const std::vector<double>& other_angles,
                      bool quiet) {
  namespace fs = std::filesystem;
  if (fs::is_directory(path)) {
    cli::status(quiet, "gsa: reading the results folder " + path);
    return read_compare_side(path);
  }
  if (!fs::exists(path))
    throw InputError(path + ": no such folder or file; give a results folder of `gsa analyse` or a grid file");
  GridSideOptions go;
  go.units = a.units;
  if (!a.fibres.empty()) {
    AnalyseFlags f;
    f.fibres = a.fibres;
    go.fibre_angles = analyse_options(f).fibre_angles;
  } else {
    go.fibre_angles = other_angles;  // the same settings as the other side's analysis
  }
  cli::status(quiet, "gsa: analysing the grid file " + path);
  return analyse_compare_side(path, go);
}

int run_compare(const CompareArgs& a, bool quiet) {
  CompareOptions o;
  o.measure = parse_measure(a.measure, "--measure");
  o.registration = parse_registration(a.registration);
  o.blank = parse_blank(a.blank);
  PlotOptions po;
  std::shared_ptr<render::DisplayGuard> display;
  if (!a.no_plots) {
    po = plot_options(a.size, a.view);
    display = render::acquire_display();  // no display: fail now, not after the work
  }
  namespace fs = std::filesystem;
  // A folder side first, so a grid side can take its fibre angles.
  const bool m_dir = fs::is_directory(a.measured), s_dir = fs::is_directory(a.simulated);
  CompareSide measured, simulated;
  if (!m_dir && s_dir) {
    simulated = load_side(a.simulated, a, {}, quiet);
    measured = load_side(a.measured, a, simulated.fibre_angles, quiet);
  } else {
    measured = load_side(a.measured, a, {}, quiet);
    simulated = load_side(a.simulated, a, measured.fibre_angles, quiet);
  }
  cli::status(quiet, "gsa: registering and mapping " + std::to_string(measured.n_marks()) + " measured marks onto " +
                         std::to_string(simulated.n_marks()) + " simulated");
  const CompareResult r = compare(measured, simulated, o);
  // The comparison's own outputs are replaced as a set; other files in the folder are kept.
  io::OutputDirOptions folder;
  folder.owned = {"differences.csv", "summary.json", "compare.vtp", "*.png", "report.html"};
  io::AtomicOutputDir out(a.out, folder);
  const std::string cmd = cli::command_line().empty() ? "gsa compare" : cli::command_line();
  const nlohmann::json summary = compare_summary(measured, simulated, r, cmd);
  write_differences_csv(out.path("differences.csv"), measured, r);
  write_compare_vtp(out.path("compare.vtp"), r);
  io::write_json(out.path("summary.json"), summary);
  std::vector<std::string> pictures;
  if (!a.no_plots) {
    auto bar = std::make_shared<std::unique_ptr<cli::Progress>>();
    pictures = write_compare_pictures(
        measured, simulated, r, po, [&out](const std::string& name) { return out.path(name); },
        [bar, quiet](int done, int total) {
          if (!*bar) *bar = std::make_unique<cli::Progress>("gsa: drawing pictures", total, quiet);
          (*bar)->update(done);
          if (done == total) (*bar)->finish();
        });
  }
  write_compare_report(out.path("report.html"), summary, pictures);
  out.commit();
  const auto& c = summary["counts"];
  const auto& st = summary["statistics"];
  std::ostringstream msg;
  msg << "gsa: " << c["matched"].get<Index>() << " of " << measured.n_marks() << " measured marks compared";
  if (c["unmatched"].get<Index>() > 0) msg << " (" << c["unmatched"].get<Index>() << " unmatched, see summary.json)";
  msg << "; registration by " << r.registration.method << ": rotation " << std::setprecision(4)
      << r.registration.transform.angle_deg() << " deg, RMS distance " << r.registration.rms << " " << measured.units;
  auto stat = [&](const char* key, const char* label) {
    if (st.contains(key) && st[key].value("n", 0) > 0)
      msg << "; " << label << " difference mean " << st[key]["mean"].get<double>() << ", RMS "
          << st[key]["rms"].get<double>();
  };
  stat("major", "major strain");
  stat("minor", "minor strain");
  if (st.contains("shape_deviation") && st["shape_deviation"].value("n", 0) > 0)
    msg << "; shape deviation RMS " << st["shape_deviation"]["rms"].get<double>() << " " << measured.units;
  msg << "; results in " << a.out;
  cli::status(quiet, msg.str());
  return cli::kExitOk;
}

}  // namespace

void add_compare_command(cli::Program& program) {
  const cli::Program* prog = &program;
  auto args = std::make_shared<CompareArgs>();
  program.add_command(
      "compare", "Compare a measured part with a simulated one: registration, per-mark differences, pictures",
      [args](CLI::App& app) {
        app.add_option("measured", args->measured, "Measured side: a results folder of gsa analyse, or a grid file")
            ->required();
        app.add_option("simulated", args->simulated,
                       "Simulated side: a results folder, or a grid file (e.g. simform run --grid-out)")
            ->required();
        app.add_option("-o,--out", args->out, "Output folder (created; files replaced only on success)")->required();
        app.add_option("--measure", args->measure,
                       "Strain measure of the major/minor differences: true (default), engineering or lagrangian");
        app.add_option("--register", args->registration,
                       "Registration of the formed parts: auto (default: by shared ids when at least 6 marks share "
                       "them, else surface), ids, surface (ICP onto the simulated fitted surface) or none");
        app.add_option("--blank", args->blank,
                       "Material coordinates: auto/fit (default: rigid fit of the blanks by shared ids or by the ICP "
                       "foot points) or same (the blanks share one frame)");
        app.add_option("--fibres", args->fibres,
                       "Fibre angles (degrees, e.g. 0,90) for grid files analysed here (default: those of a results "
                       "folder on the other side)");
        app.add_option("--units", args->units, "Length unit of grid files analysed here (default mm)");
        app.add_option("--size", args->size, "Picture size WxH in pixels (default 1200x900)");
        app.add_option("--view", args->view, "View of the formed part: auto, top, iso, front, side or x,y,z");
        app.add_flag("--no-plots", args->no_plots, "Skip the pictures (report.html still written)");
      },
      [args, prog] { return run_compare(*args, prog->common().quiet); });
}

}  // namespace sf::gsa
