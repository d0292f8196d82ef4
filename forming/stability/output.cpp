#include "forming/stability/output.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <ostream>

#include "common/cli/progress.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/csv.hpp"
#include "common/io/json.hpp"
#include "common/render/chart.hpp"
#include "common/render/display.hpp"

namespace sf::forming::stability {
namespace {

constexpr double kDeg = kPi / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const render::Colour kUnstable{0.90, 0.45, 0.40};
const render::Colour kStable{0.55, 0.72, 0.90};
const render::Colour kMixed{0.98, 0.80, 0.50};
const render::Colour kBoundary{0.1, 0.1, 0.1};
const render::Colour kRelative{0.35, 0.35, 0.35};
const render::Colour kLaminate{0.05, 0.55, 0.20};

const char* kUnitsLine =
    "# units: lengths in mm, times in s, stresses in MPa (viscosity MPa s), or any consistent set as given; "
    "angles in degrees from x1";

std::string source_name(TrellisFlow::Source s) {
  switch (s) {
    case TrellisFlow::Source::kRatesAndTensions:
      return "rates and tensions";
    case TrellisFlow::Source::kShearRateAndTensions:
      return "trellis shear rate and tensions";
    case TrellisFlow::Source::kTractions:
      return "tractions";
  }
  return "?";
}

void write_csv(const StabilityResult& r, std::ostream& out) {
  out << "# simform stability: convected growth rate of out-of-plane buckles exp(i K n.x) of a fibre-reinforced "
         "viscous sheet in trellis flow (docs/theory/stability.md)\n";
  out << kUnitsLine << "\n";
  out << "# theta_deg: wave direction n; crest_deg: crests along it + 90; wavelength = 2 pi / wave_number (mm); "
         "wave_number K (1/mm); kappa = (K h)^2 (-); resolved_tension T_n (MPa); growth_rate G (1/s); "
         "growth_rate_rel = G - D33 (1/s, relative to the thickness); growth_rate_no_fibres: sinuous mode of the "
         "same sheet without fibres, same rates (1/s); normal_to_fibre: 1 at a direction normal to a family\n";
  io::CsvWriter w(out, {"theta_deg", "crest_deg", "wavelength", "wave_number", "kappa", "resolved_tension",
                        "growth_rate", "growth_rate_rel", "growth_rate_no_fibres", "normal_to_fibre"});
  for (const ModeRow& row : r.rows)
    w.begin_row()
        .add(row.theta_deg)
        .add(row.crest_deg)
        .add(row.wavelength)
        .add(row.wave_number)
        .add(row.kappa)
        .add(row.resolved_tension)
        .add(row.growth_rate)
        .add(row.growth_rate_rel)
        .add(row.newtonian_sinuous)
        .add(row.normal_to_fibre ? 1 : 0)
        .end_row();
}

nlohmann::json summary_json(const StabilityResult& r, const OutputOptions& o, const std::vector<std::string>& files) {
  const TrellisFlow& f = r.flow;
  const SheetState& s = f.sheet;
  const Mat2 sigma = s.in_plane_stress();
  nlohmann::json j;
  j["command"] = o.command_line;
  j["input_file"] = o.input_file.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.input_file);
  j["model"] =
      "Newtonian fluid reinforced by two families of inextensible fibres through the thickness, homogeneous trellis "
      "flow, free surfaces; linear stability of buckles exp(i K n.x) (docs/theory/stability.md)";
  j["units"] = {{"length", "mm"},
                {"time", "s"},
                {"stress", "MPa"},
                {"viscosity", "MPa s"},
                {"rate", "1/s"},
                {"angle", "deg"},
                {"note", "or any consistent set, as given"}};
  j["inputs"] = {{"fibre_angles_deg", {f.fibre_angles_deg[0], f.fibre_angles_deg[1]}},
                 {"viscosity", s.viscosity},
                 {"thickness", s.thickness},
                 {"given", source_name(f.source)}};
  j["background"] = {
      {"angle_between_fibres_deg", f.fibre_angle / kDeg},
      {"bisector_deg", f.bisector_deg},
      {"rate", {{"D11", s.rate(0, 0)}, {"D22", s.rate(1, 1)}, {"D12", s.rate(0, 1)}, {"D33", s.rate33()}}},
      {"trellis_shear_rate", f.shear_rate},
      {"flow", flow_kind_name(f)},
      {"rates_projected_relative", f.projection},
      {"tensions", {{"T_a", s.fibres[0].tension}, {"T_b", s.fibres[1].tension}}},
      {"in_plane_stress", {{"sigma11", sigma(0, 0)}, {"sigma22", sigma(1, 1)}, {"sigma12", sigma(0, 1)}}},
      {"pressure", 2.0 * s.viscosity * s.rate33()}};
  const MostUnstableMode& m = r.mode;
  j["most_unstable_mode"] = {{"wave_direction_deg", m.theta_deg},
                             {"crest_direction_deg", m.crest_deg},
                             {"wavelength", nullptr},
                             {"wavelength_note", "every wavelength grows at the same rate in this model"},
                             {"resolved_tension", m.resolved_tension},
                             {"growth_rate", m.growth_rate},
                             {"growth_rate_relative_to_thickness", m.growth_rate_rel},
                             {"tau", m.tau},
                             {"normal_to_fibre", m.normal_to_fibre}};
  j["verdict"] = to_string(r.verdict);
  j["verdict_line"] = r.verdict_line;
  const double diff = std::abs(r.check.growth_rate - r.check_closed_form);
  const double scale = std::max(
      {std::abs(r.check_closed_form), std::abs(s.rate33()), std::abs(m.resolved_tension) / s.viscosity, 1e-300});
  j["numerical_check"] = {{"method",
                           "Legendre-Galerkin through the thickness; eigenvalues of the convected evolution on the "
                           "admissible displacements"},
                          {"degree", r.scan.spectral_degree},
                          {"wave_direction_deg", m.theta_deg},
                          {"wave_number", r.check_wave_number},
                          {"closed_form", r.check_closed_form},
                          {"spectral", r.check.growth_rate},
                          {"difference_relative", std::isfinite(r.check.growth_rate) ? diff / scale : kNaN},
                          {"status", r.check.ok() ? "ok" : r.check.message},
                          {"invariance_residual", r.check.invariance_residual},
                          {"n_state", r.check.n_state}};
  j["directions_normal_to_a_fibre"] = nlohmann::json::array();
  for (const StabilityResult::Exceptional& e : r.exceptional)
    j["directions_normal_to_a_fibre"].push_back(
        {{"wave_direction_deg", e.theta_deg},
         {"closed_form_limit", e.closed_form_limit},
         {"buckle_instantaneous_growth_rate", e.instantaneous},
         {"note",
          "crests along a fibre family: no normal mode in the ideal model; the buckle's instantaneous rate "
          "at the check wave number"}});
  j["scan"] = {{"wavelength_min", r.scan.min_wavelength},
               {"wavelength_max", r.scan.max_wavelength},
               {"n_wavelengths", r.scan.n_wavelengths},
               {"n_directions", r.scan.n_directions}};
  j["maps"] = {{"tau_definition", "T_n / (mu |trellis shear rate|)"},
               {"kappa_definition", "(K h)^2"},
               {"growth_factor", "G / |trellis shear rate| = s |cot chi| - tau, s = +1 thickening, -1 thinning"},
               {"boundary_tau_thickening", r.thickening_map.boundary_tau},
               {"boundary_tau_thinning", r.thinning_map.boundary_tau}};
  j["outputs"] = files;
  return j;
}

render::Chart map_chart(const StabilityResult& r, const StabilityMap& map) {
  const bool thick = map.kind == FlowKind::kThickening;
  render::Chart c;
  c.title = std::string("Stability map, ") + (thick ? "thickening" : "thinning") + " trellis flow";
  c.subtitle = fmt::format(
      "fibre families {:.1f} deg apart: G / |shear rate| = {}|cot chi| - tau = {:+.3g} - tau, "
      "for every kappa",
      map.fibre_angle / kDeg, thick ? "" : "-", map.boundary_tau);
  c.x_label = "log10 kappa,  kappa = (K h)^2  [-]";
  c.y_label = "tau = T_n / (mu |shear rate|)  [-]";
  c.footnote =
      "T_n: fibre tension resolved in the wave direction; K: wave number; h: thickness; G: convected growth "
      "rate; D33 " +
      std::string(thick ? "> 0" : "< 0");
  c.include_origin = false;
  // The grid values are cell centres; the axes run to the outer cell edges.
  const std::size_t nk = map.log10_kappa.size(), nt = map.tau.size();
  const double dk = (map.log10_kappa.back() - map.log10_kappa.front()) / static_cast<double>(nk - 1);
  const double dt = (map.tau.back() - map.tau.front()) / static_cast<double>(nt - 1);
  const double x0 = map.log10_kappa.front() - 0.5 * dk, x1 = map.log10_kappa.back() + 0.5 * dk;
  const double y0 = map.tau.front() - 0.5 * dt, y1 = map.tau.back() + 0.5 * dt;
  c.range = std::array<double, 4>{x0, x1, y0, y1};
  // Regions: each row of cells is drawn as horizontal runs of one colour, a line as wide as
  // the row (the plot area of a 1200 x 900 chart is about kPlotHeightPx high; lines are
  // clipped to the plot area at their ends).
  constexpr double kPlotHeightPx = 700.0;
  const double row_px = 1.03 * kPlotHeightPx / static_cast<double>(nt);
  auto category = [&](std::size_t jt, std::size_t ik) {
    const double g = map.growth[jt * nk + ik];
    const double g_rel = -map.tau[jt];
    return (g > 0 && g_rel > 0) ? 0 : (g <= 0 && g_rel <= 0) ? 1 : 2;
  };
  const render::Colour colours[3] = {kUnstable, kStable, kMixed};
  for (std::size_t jt = 0; jt < nt; ++jt) {
    std::size_t start = 0;
    for (std::size_t ik = 1; ik <= nk; ++ik) {
      if (ik < nk && category(jt, ik) == category(jt, start)) continue;
      render::ChartSeries run;
      run.style = render::ChartSeries::Style::kLine;
      run.colour = colours[category(jt, start)];
      run.size_px = row_px;
      run.x = {map.log10_kappa[start] - 0.5 * dk, map.log10_kappa[ik - 1] + 0.5 * dk};
      run.y = {map.tau[jt], map.tau[jt]};
      c.series.push_back(run);
      start = ik;
    }
  }
  c.extra_legend = {{render::LegendEntry::Kind::kSwatch, kUnstable, "buckles: G > 0 and G - D33 > 0"},
                    {render::LegendEntry::Kind::kSwatch, kStable, "stable: G <= 0 and G - D33 <= 0"},
                    {render::LegendEntry::Kind::kSwatch, kMixed,
                     thick ? "G > 0 >= G - D33: grows only with the thickness"
                           : "G <= 0 < G - D33: shrinks slower than the thickness"}};
  render::ChartSeries boundary;
  boundary.label = fmt::format("G = 0: tau = {:+.3g}", map.boundary_tau);
  boundary.style = render::ChartSeries::Style::kLine;
  boundary.colour = kBoundary;
  boundary.size_px = 3;
  boundary.x = {x0, x1};
  boundary.y = {map.boundary_tau, map.boundary_tau};
  c.series.push_back(boundary);
  render::ChartSeries relative = boundary;
  relative.label = "G - D33 = 0: tau = 0 (resolved tension 0)";
  relative.colour = kRelative;
  relative.dash_px = 12;
  relative.y = {0.0, 0.0};
  c.series.push_back(relative);
  const TrellisFlow& f = r.flow;
  const bool same_kind = (thick && f.thickening()) || (!thick && f.thinning()) || (!f.thickening() && !f.thinning());
  if (same_kind && std::isfinite(r.mode.tau)) {
    render::ChartSeries lam = boundary;
    lam.label = fmt::format("this laminate, most unstable direction: tau = {:.3g}", r.mode.tau);
    lam.colour = kLaminate;
    lam.size_px = 4;
    lam.y = {r.mode.tau, r.mode.tau};
    c.series.push_back(lam);
  }
  c.legend_title = "Lines and regions";
  return c;
}

render::Chart direction_chart(const StabilityResult& r) {
  render::Chart c;
  c.title = "Growth rate against buckle direction";
  c.subtitle = fmt::format("the same at every wavelength; {} flow, D33 = {:.3g} 1/s", flow_kind_name(r.flow),
                           r.flow.sheet.rate33());
  c.x_label = "wave direction theta (crests along theta + 90)  [deg]";
  c.y_label = "growth rate  [1/s]";
  c.footnote = "G: convected growth rate of the buckle amplitude; G - D33: relative to the thickness";
  render::ChartSeries g, rel;
  g.label = "G";
  g.style = render::ChartSeries::Style::kLine;
  g.colour = {0.80, 0.11, 0.09};
  g.size_px = 3;
  rel = g;
  rel.label = "G - D33";
  rel.colour = {0.09, 0.31, 0.78};
  rel.dash_px = 12;
  const int nw = r.scan.n_wavelengths;
  for (std::size_t i = 0; i < r.rows.size(); i += static_cast<std::size_t>(nw)) {
    g.x.push_back(r.rows[i].theta_deg);
    g.y.push_back(r.rows[i].growth_rate);
    rel.x.push_back(r.rows[i].theta_deg);
    rel.y.push_back(r.rows[i].growth_rate_rel);
  }
  g.x.push_back(180.0);
  g.y.push_back(g.y.front());
  rel.x.push_back(180.0);
  rel.y.push_back(rel.y.front());
  c.series = {g, rel};
  render::ChartSeries mode;
  mode.label = fmt::format("most unstable: {:.1f} deg", r.mode.theta_deg);
  mode.colour = {0.1, 0.1, 0.1};
  mode.size_px = 6;
  mode.x = {r.mode.theta_deg};
  mode.y = {r.mode.growth_rate};
  c.series.push_back(mode);
  c.legend_title = "Curves";
  return c;
}

}  // namespace

std::vector<std::string> write_stability_outputs(const StabilityResult& result, const OutputOptions& options) {
  io::OutputDirOptions folder;
  folder.owned = {"growth_rate.csv", "summary.json", "*.png"};  // an older run's maps never stay
  io::AtomicOutputDir out(options.out_dir, folder);
  std::vector<std::string> files = {"growth_rate.csv", "summary.json"};
  io::write_file_atomic(out.path("growth_rate.csv"), [&](std::ostream& os) { write_csv(result, os); });
  if (options.plots) {
    const auto display = render::acquire_display();
    const render::ImageSize size{1200, 900};
    cli::status(options.quiet, "simform: drawing the stability maps");
    render::write_chart_png(map_chart(result, result.thickening_map), size, out.path("stability_map_thickening.png"));
    render::write_chart_png(map_chart(result, result.thinning_map), size, out.path("stability_map_thinning.png"));
    render::write_chart_png(direction_chart(result), size, out.path("growth_rate_direction.png"));
    files.insert(files.end(),
                 {"stability_map_thickening.png", "stability_map_thinning.png", "growth_rate_direction.png"});
  }
  io::write_json(out.path("summary.json"), summary_json(result, options, files));
  out.commit();
  return files;
}

}  // namespace sf::forming::stability
