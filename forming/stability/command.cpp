#include "forming/stability/command.hpp"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "common/cli/app.hpp"
#include "common/cli/progress.hpp"
#include "common/core/error.hpp"
#include "forming/stability/analysis.hpp"
#include "forming/stability/input.hpp"
#include "forming/stability/output.hpp"

namespace sf::forming::stability {
namespace {

struct Args {
  std::string input;
  std::string out;
  std::vector<double> fibres, rates, tensions, tractions, wavelengths;
  double viscosity = 0, thickness = 0, shear_rate = 0, rate33 = 0;
  int n_wavelengths = 41, n_directions = 180;
  bool no_plots = false;
  CLI::App* app = nullptr;
};

bool given(const Args& a, const std::string& name) { return a.app->count(name) > 0; }

template <std::size_t N>
std::array<double, N> fixed(const std::vector<double>& v, const std::string& option, const std::string& what) {
  if (v.size() != N)
    throw UsageError(fmt::format("{}: expected {} comma-separated numbers ({}), found {}", option, N, what, v.size()));
  std::array<double, N> a{};
  std::copy(v.begin(), v.end(), a.begin());
  return a;
}

// The command line as given (for summary.json).
std::string command_line(const Args& a) {
  std::string c = "simform stability";
  if (!a.input.empty()) c += " " + a.input;
  c += " --out " + a.out;
  for (const char* name : {"--fibres", "--viscosity", "--thickness", "--rates", "--rate33", "--shear-rate",
                           "--tensions", "--tractions", "--wavelengths", "--n-wavelengths", "--n-directions"}) {
    if (!given(a, name)) continue;
    std::string v;
    for (const std::string& r : a.app->get_option(name)->results()) v += (v.empty() ? "" : ",") + r;
    c += std::string(" ") + name + " " + v;
  }
  if (a.no_plots) c += " --no-plots";
  return c;
}

int run(Args& a, bool quiet) {
  StabilityInput in;
  if (!a.input.empty()) in = read_stability_input(a.input);
  TrellisSpec& spec = in.spec;

  if (given(a, "--fibres")) {
    spec.fibre_angles_deg = fixed<2>(a.fibres, "--fibres", "angles of families a and b in degrees");
    spec.fibres_at = "--fibres";
    in.has_fibres = true;
  }
  if (given(a, "--viscosity")) {
    spec.viscosity = a.viscosity;
    spec.viscosity_at = "--viscosity";
    in.has_viscosity = true;
  }
  if (given(a, "--thickness")) {
    spec.thickness = a.thickness;
    spec.thickness_at = "--thickness";
    in.has_thickness = true;
  }
  if (given(a, "--rates")) {
    spec.rates = fixed<3>(a.rates, "--rates", "D11, D22, D12 in 1/s");
    spec.rates_at = "--rates";
    spec.shear_rate.reset();
  }
  if (given(a, "--rate33")) {
    spec.rate33 = a.rate33;
    spec.rate33_at = "--rate33";
  }
  if (given(a, "--shear-rate")) {
    spec.shear_rate = a.shear_rate;
    spec.shear_rate_at = "--shear-rate";
    if (!given(a, "--rates")) spec.rates.reset(), spec.rate33.reset();
  }
  if (given(a, "--tensions")) {
    spec.tensions = fixed<2>(a.tensions, "--tensions", "T_a, T_b in MPa");
    spec.tensions_at = "--tensions";
    if (!given(a, "--tractions")) spec.tractions.reset();
  }
  if (given(a, "--tractions")) {
    spec.tractions = fixed<3>(a.tractions, "--tractions", "sigma11, sigma22, sigma12 in MPa");
    spec.tractions_at = "--tractions";
    if (!given(a, "--tensions")) spec.tensions.reset();
    if (!given(a, "--rates") && !given(a, "--shear-rate")) spec.rates.reset(), spec.shear_rate.reset();
  }
  if (given(a, "--wavelengths")) {
    const auto w = fixed<2>(a.wavelengths, "--wavelengths", "min, max in mm");
    if (!(w[0] > 0.0) || !(w[1] > w[0]))
      throw InputError(fmt::format("--wavelengths: expected 0 < min < max (mm), found {}, {}", w[0], w[1]));
    in.scan.min_wavelength = w[0];
    in.scan.max_wavelength = w[1];
  }
  if (given(a, "--n-wavelengths")) in.scan.n_wavelengths = a.n_wavelengths;
  if (given(a, "--n-directions")) in.scan.n_directions = a.n_directions;

  // Required pieces: an option without a file (usage), a key with one (bad input).
  const struct {
    bool have;
    const char* option;
    const char* key;
  } required[] = {{in.has_fibres, "--fibres", "fibres"},
                  {in.has_viscosity, "--viscosity", "viscosity"},
                  {in.has_thickness, "--thickness", "thickness"}};
  for (const auto& r : required) {
    if (r.have) continue;
    if (a.input.empty())
      throw UsageError(std::string(r.option) + " is required without an input file (or give INPUT.yaml)");
    throw InputError(in.at + ": stability input: missing required key '" + r.key + "' (or give " + r.option + ")");
  }

  const TrellisFlow flow = build_trellis_flow(spec);
  if (flow.projection > 1e-12)
    sf::cli::status(quiet, fmt::format("simform: the rates were projected onto the trellis rates (relative change "
                                       "{:.2g}, within the tolerance {:g})",
                                       flow.projection, kRateTolerance));
  sf::cli::status(quiet, fmt::format("simform: {} trellis flow, fibres {:g} and {:g} deg, shear rate {:.4g} 1/s, "
                                     "T_a = {:.4g} MPa, T_b = {:.4g} MPa",
                                     flow_kind_name(flow), flow.fibre_angles_deg[0], flow.fibre_angles_deg[1],
                                     flow.shear_rate, flow.sheet.fibres[0].tension, flow.sheet.fibres[1].tension));
  const StabilityResult result = analyse_stability(flow, in.scan);
  if (!result.check.ok())
    sf::cli::status(quiet, "simform: note: numerical check at the most unstable direction: " + result.check.brief());

  OutputOptions o;
  o.out_dir = a.out;
  o.plots = !a.no_plots;
  o.input_file = a.input;
  o.quiet = quiet;
  o.command_line = command_line(a);
  const std::vector<std::string> files = write_stability_outputs(result, o);

  std::cout << result.mode_line << "\n" << result.verdict_line << "\n";
  sf::cli::status(quiet, fmt::format("simform: wrote {} files to {} (numerical check: closed form {:.6g} 1/s, "
                                     "spectral {:.6g} 1/s)",
                                     files.size(), a.out, result.check_closed_form, result.check.growth_rate));
  return sf::cli::kExitOk;
}

}  // namespace

void add_stability_command(sf::cli::Program& program) {
  const sf::cli::Program* prog = &program;
  auto args = std::make_shared<Args>();
  program.add_command(
      "stability",
      "Buckling stability of a trellis flow: growth rate over wavelength and buckle direction, most unstable mode, "
      "verdict, stability maps",
      [args](CLI::App& app) {
        args->app = &app;
        app.add_option("input", args->input, "Input file (YAML, see docs/forming.md); options override its values");
        app.add_option("-o,--out", args->out, "Output folder (replaced only when written completely)")->required();
        app.add_option("--fibres", args->fibres, "Angles of fibre families a and b: A,B (degrees from x1)")
            ->delimiter(',');
        app.add_option("--viscosity", args->viscosity, "Viscosity mu (MPa s)");
        app.add_option("--thickness", args->thickness, "Sheet thickness h (mm)");
        app.add_option("--rates", args->rates, "In-plane rates of deformation D11,D22,D12 (1/s)")->delimiter(',');
        app.add_option("--rate33", args->rate33, "D33 (1/s), checked against -(D11 + D22)");
        app.add_option("--shear-rate", args->shear_rate,
                       "Trellis shear rate: rate at which the angle between the families closes (1/s)");
        app.add_option("--tensions", args->tensions, "Fibre tensions T_a,T_b (MPa)")->delimiter(',');
        app.add_option("--tractions", args->tractions,
                       "In-plane stress sigma11,sigma22,sigma12 (MPa, through-thickness mean); determines the shear "
                       "rate and both tensions")
            ->delimiter(',');
        app.add_option("--wavelengths", args->wavelengths, "Wavelength range MIN,MAX (mm; default 0.5 h to 200 h)")
            ->delimiter(',');
        app.add_option("--n-wavelengths", args->n_wavelengths, "Wavelengths sampled (log-spaced, default 41)")
            ->check(CLI::Range(2, 10000));
        app.add_option("--n-directions", args->n_directions, "Buckle directions sampled over 180 deg (default 180)")
            ->check(CLI::Range(4, 36000));
        app.add_flag("--no-plots", args->no_plots, "Skip the PNG pictures");
      },
      [args, prog] { return run(*args, prog->common().quiet); });
}

}  // namespace sf::forming::stability
