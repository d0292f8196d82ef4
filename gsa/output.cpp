#include "gsa/output.hpp"

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <fstream>
#include <future>
#include <limits>
#include <sstream>

#include "common/core/parallel.hpp"
#include "common/core/error.hpp"
#include "common/fe/surface_field.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/csv.hpp"
#include "common/io/json.hpp"
#include "common/io/vtk_xml.hpp"
#include "gsa/measured_region.hpp"
#include "gsa/surfaces_file.hpp"

namespace sf::gsa {

io::OutputDirOptions analyse_results_folder() {
  io::OutputDirOptions o;
  o.owned = {"strains.csv", "summary.json", "undeformed.vtp", "deformed.vtp",       "samples.csv",
             "*.png",       "report.html",  "surfaces.json",  "series_strains.csv", "strain_paths.csv",
             "series.pvd",  "stages",       "view.html",      "section_*.csv"};
  return o;
}

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

const char* method_name(Method m) { return m == Method::kSurface ? "surface" : "triangles"; }

// All per-point scalar fields derived from a strain (NaN when absent).
struct Fields {
  double lambda1 = kNaN, lambda2 = kNaN, e1 = kNaN, e2 = kNaN, eng1 = kNaN, eng2 = kNaN, true1 = kNaN, true2 = kNaN,
         thick = kNaN;
  Vec3 dir1 = Vec3::Constant(kNaN), dir2 = Vec3::Constant(kNaN), dir1u = Vec3::Constant(kNaN),
       dir2u = Vec3::Constant(kNaN);
};
Fields fields_of(const std::optional<SurfaceStrain>& s) {
  Fields f;
  if (!s) return f;
  f.lambda1 = s->lambda1;
  f.lambda2 = s->lambda2;
  f.e1 = s->green(0);
  f.e2 = s->green(1);
  f.eng1 = s->engineering(0);
  f.eng2 = s->engineering(1);
  f.true1 = s->true_strain(0);
  f.true2 = s->true_strain(1);
  f.thick = s->thickness_change_pct();
  f.dir1 = s->dir1_deformed;
  f.dir2 = s->dir2_deformed;
  f.dir1u = s->dir1_undeformed;
  f.dir2u = s->dir2_undeformed;
  return f;
}

nlohmann::json json_number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

nlohmann::json range_of(const std::vector<double>& v) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double x : v)
    if (std::isfinite(x)) lo = std::min(lo, x), hi = std::max(hi, x);
  if (!std::isfinite(lo)) return nullptr;
  return {{"min", lo}, {"max", hi}};
}
}  // namespace

void OutputOptions::validate() const {
  if (sample < 0 || sample > 50)
    throw OptionError("sample", "expected 0..50 points per element side, found " + std::to_string(sample));
}

std::vector<std::string> strain_columns(const AnalysisResult& result) {
  std::vector<std::string> c = {"id",
                                "status",
                                "element",
                                "xi1",
                                "xi2",
                                "lambda1",
                                "lambda2",
                                "E1",
                                "E2",
                                "eng1",
                                "eng2",
                                "true1",
                                "true2",
                                "thickness_change_pct",
                                "dir1_x",
                                "dir1_y",
                                "dir1_z",
                                "dir2_x",
                                "dir2_y",
                                "dir2_z",
                                "dir1u_x",
                                "dir1u_y",
                                "dir1u_z",
                                "residual",
                                "residual_undeformed",
                                "X_fit",
                                "Y_fit",
                                "Z_fit",
                                "flag_reason",
                                "flag_deviation",
                                "flag_threshold",
                                "flag_noise"};
  if (result.fibre_angles.size() == 2) {
    for (const char* f : {"fibre1", "fibre2"})
      for (const char* s : {"_x", "_y", "_z", "_stretch"}) c.push_back(std::string(f) + s);
    c.push_back("shear_angle_deg");
  }
  return c;
}

void write_strains_csv(const std::string& path, const GridData& grid, const AnalysisResult& result,
                       const OutputOptions& options, const FlcMargins* margins, const PressColumns* press) {
  const bool mid = press && !press->mid.empty();
  const FlcAssessment* assessment = press && press->assessment ? &*press->assessment : nullptr;
  std::ofstream out(path);
  if (!out) throw Error(path + ": cannot write");
  out << "# gsa strains; lengths in " << options.units << "; strains dimensionless (E = Green-Lagrange, "
      << "eng = engineering, true = logarithmic); E1 >= E2; dir1 = major direction on the deformed surface, "
      << "dir1u on the undeformed; residual = distance of the deformed mark from the fitted deformed surface ("
      << options.units
      << "); flag_* = why a point was flagged (its deviation from its neighbours' local fit, the threshold "
      << "it exceeded, the noise level; " << options.units << "), flagged points keep the fitted surfaces' strain"
      << "; thickness by incompressibility; method " << method_name(result.method) << "\n";
  if (mid)
    out << "# mid_major, mid_minor: principal " << measure_word(options.measure)
        << " strains of the sheet's mid-surface (grid on the "
        << (options.mid.face == GridFace::kTop ? "top" : "bottom") << " face, initial thickness "
        << options.mid.thickness << " " << options.units << "); thickness_mm: current thickness in " << options.units
        << " (incompressible mid-surface)\n";
  if (margins) out << flc_margin_comment(*margins) << "\n";
  if (assessment)
    out << "# flc_radial_margin: distance along the mark's proportional strain path from the origin to the curve "
           "minus its distance (strain); zone: failure, necking_risk (within "
        << assessment->options.necking_margin << "), excess_thinning (beyond " << assessment->options.thinning_limit_pct
        << " %), compression (below the pure-shear line), "
        << "insufficient_stretch (major below " << assessment->options.min_stretch
        << "), safe, outside_curve; assessed on the " << assessment->strains << " strains\n";
  std::vector<std::string> columns = strain_columns(result);
  if (mid)
    for (const std::string& c : {std::string("mid_major"), std::string("mid_minor"), "thickness_" + options.units})
      columns.push_back(c);
  if (margins) columns.push_back("flc_margin");
  if (assessment)
    for (const char* c : {"flc_radial_margin", "zone"}) columns.push_back(c);
  std::unique_ptr<fe::SurfaceField> fu;
  if (result.method == Method::kSurface)
    fu = std::make_unique<fe::SurfaceField>(result.mesh, result.undeformed_parameters);
  // Rows [begin, end) as text (formatting numbers is most of the time: large
  // tables are formatted in two halves at once).
  auto rows = [&](Index begin, Index end, bool header) {
    std::ostringstream text;
    io::CsvWriter w = header ? io::CsvWriter(text, columns) : io::CsvWriter(text, columns.size());
    for (Index p = begin; p < end; ++p) {
      const PointResult& pr = result.points[p];
      const Fields f = fields_of(pr.strain);
      w.begin_row().add(grid.ids[p]).add(pr.status);
      if (pr.element >= 0)
        w.add(pr.element).add(pr.xi[0]).add(pr.xi[1]);
      else
        w.add(kNaN).add(kNaN).add(kNaN);
      w.add(f.lambda1).add(f.lambda2).add(f.e1).add(f.e2).add(f.eng1).add(f.eng2).add(f.true1).add(f.true2).add(
          f.thick);
      for (const Vec3* v : {&f.dir1, &f.dir2, &f.dir1u}) w.add((*v)[0]).add((*v)[1]).add((*v)[2]);
      w.add(pr.residual).add(pr.residual_undeformed);
      Vec3 xf = Vec3::Constant(kNaN);
      if (fu && pr.element >= 0) xf = fu->evaluate3(pr.element, pr.xi, basis::kValues).x;
      w.add(xf[0]).add(xf[1]).add(xf[2]);
      if (pr.flag)
        w.add(std::string(code(pr.flag->reason))).add(pr.flag->deviation).add(pr.flag->threshold).add(pr.flag->noise);
      else
        w.add(std::string()).add(kNaN).add(kNaN).add(kNaN);
      if (result.fibre_angles.size() == 2) {
        for (int k = 0; k < 2; ++k) {
          if (pr.fibres.size() == 2 && pr.strain)
            w.add(pr.fibres[k].direction[0])
                .add(pr.fibres[k].direction[1])
                .add(pr.fibres[k].direction[2])
                .add(pr.fibres[k].stretch);
          else
            w.add(kNaN).add(kNaN).add(kNaN).add(kNaN);
        }
        w.add(pr.strain ? pr.shear_angle_deg : kNaN);
      }
      const std::size_t q = static_cast<std::size_t>(p);
      if (mid) {
        const auto& m = press->mid[q];
        if (m && pr.strain)
          w.add(principal_strain(m->strain, 0, options.measure))
              .add(principal_strain(m->strain, 1, options.measure))
              .add(m->thickness);
        else
          w.add(kNaN).add(kNaN).add(kNaN);
      }
      if (margins) w.add(margins->margin[q]);
      if (assessment) w.add(assessment->radial_margin[q]).add(std::string(zone_code(assessment->zone[q])));
      w.end_row();
    }
    return text.str();
  };
  // Chunks of rows formatted on all cores, a few per thread at a time, and written in
  // order: the text is the same byte for byte whatever the threads, and only a few chunks
  // are held at once (the whole table at 1e6 points is 0.5 GB of text).
  const Index n = grid.n_points();
  constexpr Index kChunk = 8192;
  const Index chunks = std::max<Index>(1, (n + kChunk - 1) / kChunk);
  const Index wave = 2 * static_cast<Index>(default_threads());
  std::vector<std::string> text(static_cast<std::size_t>(std::min(chunks, wave)));
  for (Index first = 0; first < chunks; first += wave) {
    const Index count = std::min(wave, chunks - first);
    parallel_for(
        count,
        [&](Index i) {
          const Index c = first + i;
          text[static_cast<std::size_t>(i)] = rows(c * kChunk, std::min(n, (c + 1) * kChunk), c == 0);
        },
        1);
    for (Index i = 0; i < count; ++i) {
      std::string& t = text[static_cast<std::size_t>(i)];
      out.write(t.data(), static_cast<std::streamsize>(t.size()));
      std::string().swap(t);
    }
  }
  if (!out) throw Error(path + ": write failed");
}

nlohmann::json make_summary(const GridData& grid, const AnalysisResult& r, const OutputOptions& options,
                            const RunInfo& info) {
  nlohmann::json j;
  j["tool"] = "gsa analyse";
  j["version"] = SF_VERSION;
  j["command_line"] = info.command_line;
  j["inputs"] = info.inputs;
  j["units"] = {
      {"length", options.units}, {"strain", "dimensionless"}, {"thickness_change", "percent"}, {"angles", "degrees"}};
  std::map<std::string, Index> counts;
  std::vector<double> e1, e2, th, eng1, eng2, true1, true2, shear;
  for (const PointResult& p : r.points) {
    ++counts[p.status];
    if (!p.strain) continue;
    e1.push_back(p.strain->green(0));
    e2.push_back(p.strain->green(1));
    eng1.push_back(p.strain->engineering(0));
    eng2.push_back(p.strain->engineering(1));
    true1.push_back(p.strain->true_strain(0));
    true2.push_back(p.strain->true_strain(1));
    th.push_back(p.strain->thickness_change_pct());
    shear.push_back(p.shear_angle_deg);
  }
  j["counts"] = {{"points", grid.n_points()}, {"by_status", counts}};
  nlohmann::json params;
  params["method"] = method_name(r.method);
  if (r.method == Method::kSurface) {
    params["mesh"] = {{"elements", r.mesh.n_elements()},
                      {"grid", r.mesh_layout},
                      {"nodes", r.mesh.n_nodes()},
                      {"unknowns_per_coordinate", r.mesh.n_dofs()},
                      {"element_type", "bicubic Hermite, arc-length scale factors"},
                      {"plane_origin", {r.centroid[0], r.centroid[1], r.centroid[2]}},
                      {"plane_axis1", {r.axis1[0], r.axis1[1], r.axis1[2]}},
                      {"refinement_rounds", r.refinement_rounds},
                      {"smallest_element", r.refinement_rounds > 0 ? nlohmann::json(r.smallest_element) : nullptr},
                      {"plane_axis2", {r.axis2[0], r.axis2[1], r.axis2[2]}}};
    params["penalty"] = r.penalty_kind == PenaltyKind::kThirdOrder ? "third-order (gamma) with edge jumps"
                        : r.penalty_kind == PenaltyKind::kJumps    ? "fourth-order edge jumps (delta)"
                                                                   : "sobolev (alpha, beta)";
    params["smoothing_automatic"] = r.smoothing_automatic;
    params["undeformed"] = {{"alpha", r.penalty_undeformed.alpha},
                            {"beta", r.penalty_undeformed.beta},
                            {"gamma", r.penalty_undeformed.gamma},
                            {"delta", r.penalty_undeformed.delta}};
    params["deformed"] = {{"alpha", r.penalty_deformed.alpha},
                          {"beta", r.penalty_deformed.beta},
                          {"gamma", r.penalty_deformed.gamma},
                          {"delta", r.penalty_deformed.delta},
                          {"boundary_third_order", r.penalty_deformed.boundary},
                          {"smooths", "displacement less its best-fit rigid motion"}};
    const Eigen::AngleAxisd turn(r.rigid.rotation);
    params["rigid_motion"] = {
        {"rotation_deg", turn.angle() * 180.0 / kPi},
        {"rotation_axis", {turn.axis()[0], turn.axis()[1], turn.axis()[2]}},
        {"translation", {r.rigid.translation[0], r.rigid.translation[1], r.rigid.translation[2]}}};
    params["noise_estimate"] = r.noise_estimate;
    params["mark_spacing"] = r.mark_spacing;
    params["gauge_length"] = r.gauge_length;
    params["projection_iterations"] = r.projection_iterations;
    params["outlier_sigma"] = r.outlier_sigma;
    nlohmann::json smoothing = {
        {"criterion", r.smoothing_criterion.empty() ? nullptr : nlohmann::json(r.smoothing_criterion)},
        {"log10_delta_optimum", json_number(r.log10_delta_optimum)},
        {"criterion_value", json_number(r.smoothing_criterion_value)},
        {"gauge_length", r.gauge_length},
        {"relaxed_elements", r.relaxed_elements},
        {"local_gauge_length", r.relaxed_elements > 0 ? nlohmann::json(r.local_gauge_length) : nullptr}};
    params["smoothing"] = smoothing;
    auto weights = [](const SigmaWeights& w) {
      if (!w.used) return nlohmann::json{{"used", false}};
      return nlohmann::json{{"used", true},
                            {"sigma_ref", w.sigma_ref},
                            {"points_with_sigma", w.n_with_sigma},
                            {"points_at_floor", w.n_floored},
                            {"points_left_out", w.n_left_out},
                            {"min_weight", w.min_weight},
                            {"max_weight", w.max_weight}};
    };
    params["weights"] = {
        {"rule",
         "w = (sigma_ref / sigma)^2 from the input's per-point sigma, sigma_ref = median sigma (equal sigmas: "
         "the unweighted fit); weight 1 where a point has no sigma; sigma below 0.01 sigma_ref counts as that; weight "
         "below 1e-6 is 0 (left out); --no-sigma-weights: all 1"},
        {"undeformed", weights(r.weights_undeformed)},
        {"deformed", weights(r.weights_deformed)}};
    if (r.noise.sigma_total() > 0 || r.noise_undeformed.sigma_total() > 0) {
      auto model = [](const NoiseEstimate& e) {
        return nlohmann::json{{"sigma_correlated", e.sigma_correlated},
                              {"correlation_length", e.correlation_length},
                              {"sigma_white", e.sigma_white},
                              {"sigma_total", e.sigma_total()},
                              {"sigma_tangent", e.sigma_tangent},
                              {"sigma_normal", e.sigma_normal}};
      };
      params["noise_model"] = {{"undeformed", model(r.noise_undeformed)},
                               {"deformed", model(r.noise)},
                               {"displacement", model(r.noise_displacement)},
                               {"meaning",
                                "per coordinate; covariance sigma_correlated^2 exp(-r^2 / (2 L^2)) + "
                                "sigma_white^2 [same point], L = correlation_length; deformed: of the "
                                "displacement noise, both states together; sigma_tangent, sigma_normal: per "
                                "tangential component and along the fitted surface's normal, from the deformed "
                                "fit's residuals (0: not estimated); displacement: where the undeformed positions are exact "
                                "(undeformed all 0), the estimate from local quadratic and quartic fits of the "
                                "displacement, its correlation length used where both fits agree (else 0: "
                                "independent noise)"}};
    }
    nlohmann::json flagged = nlohmann::json::array();
    for (std::size_t p = 0; p < r.points.size(); ++p) {
      const PointResult& pr = r.points[p];
      if (!pr.flag) continue;
      nlohmann::json f = {{"id", grid.ids[p]},
                          {"status", pr.status},
                          {"reason", code(pr.flag->reason)},
                          {"deviation", pr.flag->deviation},
                          {"threshold", pr.flag->threshold},
                          {"noise", pr.flag->noise}};
      const Eigen::RowVector3d at =
          grid.has_deformed(static_cast<Index>(p)) ? grid.deformed.row(p) : grid.undeformed.row(p);
      if (at.allFinite()) f["position"] = {at[0], at[1], at[2]};
      f["position_state"] = grid.has_deformed(static_cast<Index>(p)) ? "deformed" : "undeformed";
      flagged.push_back(std::move(f));
    }
    j["outliers"] = {{"sigma", r.outlier_sigma},
                     {"noise_undeformed", r.noise_outliers_undeformed},
                     {"noise_deformed", r.noise_outliers_deformed},
                     {"noise_deformed_axis", r.noise_outliers_deformed_axis},
                     {"noise_deformed_across", r.noise_outliers_deformed_across},
                     {"rule",
                      "isolated points only: deviation from the local quadratic of the 16 nearest neighbours "
                      "above sigma x noise and 2.5 x the second largest among the 8 nearest (deformed: the noisiest-axis and "
                      "across-axis parts each in its own noise level: the Mahalanobis length under a robust noise covariance); "
                      "flagged points keep a strain"},
                     {"flagged", flagged}};
    j["fit"] = {{"undeformed", {{"rms_residual", r.rms_undeformed}, {"max_residual", r.max_undeformed}}},
                {"deformed", {{"rms_residual", r.rms_deformed}, {"max_residual", r.max_deformed}}}};
  } else {
    params["triangles"] = r.n_triangles;
  }
  if (!r.fibre_angles.empty()) params["fibre_angles_deg"] = r.fibre_angles;
  j["parameters"] = params;
  j["strain_ranges"] = {{"E1", range_of(e1)},
                        {"E2", range_of(e2)},
                        {"eng1", range_of(eng1)},
                        {"eng2", range_of(eng2)},
                        {"true1", range_of(true1)},
                        {"true2", range_of(true2)},
                        {"thickness_change_pct", range_of(th)}};
  if (r.fibre_angles.size() == 2) j["strain_ranges"]["shear_angle_deg"] = range_of(shear);
  j["timings_s"] = {{"read", r.times.read}, {"mesh", r.times.mesh},     {"project", r.times.project},
                    {"fit", r.times.fit},   {"strain", r.times.strain}, {"write", r.times.write}};
  j["timings_s"].update({{"outliers", r.times.outliers}, {"noise", r.times.noise}, {"choice", r.times.choice}});
  j["warnings"] = r.warnings;
  return j;
}

std::vector<std::optional<MidSurfaceStrain>> mark_mid_strains(const AnalysisResult& r, const MidSurfaceOptions& o) {
  std::vector<std::optional<MidSurfaceStrain>> out(r.points.size());
  if (!o.enabled() || r.method != Method::kSurface) return out;
  const fe::SurfaceField fu(r.mesh, r.undeformed_parameters), fd(r.mesh, r.deformed_parameters);
  const unsigned all = basis::kValues | basis::kFirst | basis::kSecond;
  for (std::size_t p = 0; p < r.points.size(); ++p) {
    const PointResult& pr = r.points[p];
    if (!pr.strain || pr.element < 0) continue;
    out[p] = mid_surface_strain(fu.evaluate3(pr.element, pr.xi, all), fd.evaluate3(pr.element, pr.xi, all), o);
  }
  return out;
}

MarkStrains assessed_strains(const AnalysisResult& r, const std::vector<std::optional<MidSurfaceStrain>>& mid,
                             StrainMeasure measure) {
  MarkStrains m = mark_strains(r, measure);
  if (mid.empty()) return m;
  for (std::size_t p = 0; p < m.major.size() && p < mid.size(); ++p) {
    if (!std::isfinite(m.major[p])) continue;
    m.major[p] = mid[p] ? principal_strain(mid[p]->strain, 0, measure) : kNaN;
    m.minor[p] = mid[p] ? principal_strain(mid[p]->strain, 1, measure) : kNaN;
  }
  return m;
}

io::PolyMesh surface_polymesh(const AnalysisResult& r, bool deformed, int subdiv, const MidSurfaceOptions& mid,
                              const std::vector<bool>* measured_given) {
  io::PolyMesh pm;
  const fe::SurfaceField fu(r.mesh, r.undeformed_parameters), fd(r.mesh, r.deformed_parameters);
  const Index ne = r.mesh.n_elements();
  const int np = subdiv + 1;
  pm.points.resize(ne * np * np, 3);
  std::vector<std::string> names = {"E1",      "E2",     "eng1", "eng2", "true1", "true2", "thickness_change_pct",
                                    "lambda1", "lambda2"};
  std::vector<io::FieldArray> scalars(names.size());
  for (std::size_t k = 0; k < names.size(); ++k) scalars[k] = {names[k], 1, {}};
  io::FieldArray dir1{"dir1", 3, {}}, dir2{"dir2", 3, {}}, disp{"displacement", 3, {}}, shear{"shear_angle_deg", 1, {}};
  io::FieldArray f1{"fibre1", 3, {}}, f2{"fibre2", 3, {}}, s1{"fibre1_stretch", 1, {}}, s2{"fibre2_stretch", 1, {}};
  const bool fibres = r.fibre_angles.size() == 2;
  io::FieldArray ml1{"mid_lambda1", 1, {}}, ml2{"mid_lambda2", 1, {}}, mth{"thickness", 1, {}};
  const unsigned updates = basis::kValues | basis::kFirst | (mid.enabled() ? basis::kSecond : 0u);
  // Only the cells where the marks are (gsa/measured_region.hpp); every point is kept, so
  // element e's points stay at e (subdiv + 1)^2 onwards.
  const std::vector<bool> measured = measured_given ? *measured_given : measured_cells(r, subdiv);
  std::vector<double> kept_element;
  Index pt = 0;
  for (Index e = 0; e < ne; ++e) {
    for (int j = 0; j < np; ++j)
      for (int i = 0; i < np; ++i, ++pt) {
        const Vec2 xi(static_cast<double>(i) / subdiv, static_cast<double>(j) / subdiv);
        const auto b = basis::BicubicHermite::evaluate(xi, updates);
        const fe::SurfacePoint pu = fu.evaluate3(e, b), pd = fd.evaluate3(e, b);
        pm.points.row(pt) = (deformed ? pd.x : pu.x).transpose();
        if (mid.enabled()) {
          const auto m = mid_surface_strain(pu, pd, mid);
          ml1.values.push_back(m ? m->strain.lambda1 : kNaN);
          ml2.values.push_back(m ? m->strain.lambda2 : kNaN);
          mth.values.push_back(m ? m->thickness : kNaN);
        }
        const auto s = surface_strain(pu.dx, pd.dx);
        const Fields f = fields_of(s);
        const double vals[] = {f.e1, f.e2, f.eng1, f.eng2, f.true1, f.true2, f.thick, f.lambda1, f.lambda2};
        for (std::size_t k = 0; k < names.size(); ++k) scalars[k].values.push_back(vals[k]);
        const Vec3& d1 = deformed ? f.dir1 : f.dir1u;
        const Vec3& d2 = deformed ? f.dir2 : f.dir2u;
        for (int c = 0; c < 3; ++c) {
          dir1.values.push_back(d1[c]);
          dir2.values.push_back(d2[c]);
          disp.values.push_back(pd.x[c] - pu.x[c]);
        }
        if (fibres) {
          // Fibre directions (undeformed or deformed surface), stretches and shear angle.
          Vec3 a[2] = {Vec3::Constant(kNaN), Vec3::Constant(kNaN)};
          double st[2] = {kNaN, kNaN};
          const FibrePair fp = fibre_pair(pu.dx, pd.dx, r.fibre_angles[0], r.fibre_angles[1]);
          for (int k = 0; k < 2; ++k) {
            if (!fp.state[k]) continue;
            a[k] = deformed ? fp.state[k]->direction_deformed : *fp.undeformed[k];
            st[k] = fp.state[k]->stretch;
          }
          const double ang = fp.shear_angle_deg;
          for (int c = 0; c < 3; ++c) {
            f1.values.push_back(a[0][c]);
            f2.values.push_back(a[1][c]);
          }
          s1.values.push_back(st[0]);
          s2.values.push_back(st[1]);
          shear.values.push_back(ang);
        }
      }
    const Index base = e * np * np;
    for (int j = 0; j < subdiv; ++j)
      for (int i = 0; i < subdiv; ++i) {
        if (!measured[static_cast<std::size_t>((e * subdiv + j) * subdiv + i)]) continue;
        const Index a = base + j * np + i;
        pm.polygons.push_back({a, a + 1, a + np + 1, a + np});
        kept_element.push_back(static_cast<double>(e));
      }
  }
  for (auto& s : scalars) pm.point_data.push_back(std::move(s));
  pm.point_data.push_back(std::move(dir1));
  pm.point_data.push_back(std::move(dir2));
  pm.point_data.push_back(std::move(disp));
  if (fibres) {
    for (auto* f : {&f1, &f2, &s1, &s2, &shear}) pm.point_data.push_back(std::move(*f));
  }
  if (mid.enabled())
    for (auto* f : {&ml1, &ml2, &mth}) pm.point_data.push_back(std::move(*f));
  pm.cell_data.push_back(io::FieldArray{"element", 1, std::move(kept_element)});
  return pm;
}

void write_samples_csv(const std::string& path, const AnalysisResult& r, const OutputOptions& options) {
  std::ofstream out(path);
  if (!out) throw Error(path + ": cannot write");
  out << "# gsa fields on a regular xi sampling (" << options.sample << " x " << options.sample
      << " per element); positions in " << options.units << "\n";
  io::CsvWriter w(out, {"element", "xi1", "xi2", "X", "Y", "Z", "x", "y", "z", "E1", "E2", "thickness_change_pct",
                        "dir1_x", "dir1_y", "dir1_z"});
  const fe::SurfaceField fu(r.mesh, r.undeformed_parameters), fd(r.mesh, r.deformed_parameters);
  const int ns = options.sample;
  for (Index e = 0; e < r.mesh.n_elements(); ++e)
    for (int j = 0; j < ns; ++j)
      for (int i = 0; i < ns; ++i) {
        const Vec2 xi((i + 0.5) / ns, (j + 0.5) / ns);
        const auto b = basis::BicubicHermite::evaluate(xi, basis::kValues | basis::kFirst);
        const fe::SurfacePoint pu = fu.evaluate3(e, b), pd = fd.evaluate3(e, b);
        const Fields f = fields_of(surface_strain(pu.dx, pd.dx));
        w.begin_row().add(e).add(xi[0]).add(xi[1]).add(pu.x[0]).add(pu.x[1]).add(pu.x[2]).add(pd.x[0]).add(pd.x[1]).add(
            pd.x[2]);
        w.add(f.e1).add(f.e2).add(f.thick).add(f.dir1[0]).add(f.dir1[1]).add(f.dir1[2]);
        w.end_row();
      }
}

namespace {
// summary.json: "mid_surface", "forming_limit" and "sections" (docs/usage.md).
void add_press_summary(nlohmann::json& j, const AnalysisResult& r, const OutputOptions& o, const WrittenResults& w) {
  if (!w.press.mid.empty()) {
    std::vector<double> mj, mn, th;
    Index n = 0;
    Vec3 normal = Vec3::Zero();
    for (std::size_t p = 0; p < w.press.mid.size(); ++p) {
      const auto& m = w.press.mid[p];
      if (!m) continue;
      ++n;
      mj.push_back(principal_strain(m->strain, 0, o.measure));
      mn.push_back(principal_strain(m->strain, 1, o.measure));
      th.push_back(m->thickness);
      normal += m->strain.normal_undeformed;
    }
    j["mid_surface"] = {
        {"initial_thickness", o.mid.thickness},
        {"grid_face", o.mid.face == GridFace::kTop ? "top" : "bottom"},
        {"mean_undeformed_normal",
         n > 0 ? nlohmann::json{normal.normalized()[0], normal.normalized()[1], normal.normalized()[2]}
               : nlohmann::json(nullptr)},
        {"measure", measure_word(o.measure)},
        {"marks", n},
        {"mid_major", range_of(mj)},
        {"mid_minor", range_of(mn)},
        {"thickness", range_of(th)},
        {"formula",
         "mid-surface r - s h/2 n (s = +1 top, -1 bottom face), tangents from the fits' second derivatives; h = "
         "t0 / (lambda1 lambda2) of the mid-surface (docs/theory/strain.md)"}};
    j["units"]["thickness"] = o.units;
  }
  if (w.press.assessment && w.margins) {
    const FlcAssessment& a = *w.press.assessment;
    double min_radial = kNaN;
    for (double x : a.radial_margin)
      if (std::isfinite(x) && !(min_radial <= x)) min_radial = x;
    j["forming_limit"] = {{"curve", a.curve},
                          {"measure", measure_word(o.measure)},
                          {"strains", a.strains},
                          {"necking_margin", a.options.necking_margin},
                          {"thinning_limit_pct", a.options.thinning_limit_pct},
                          {"min_stretch", a.options.min_stretch},
                          {"marks_assessed", w.margins->n_marks},
                          {"marks_beyond", w.margins->n_beyond},
                          {"min_margin", json_number(w.margins->min_margin)},
                          {"min_radial_margin", json_number(min_radial)},
                          {"zones", a.counts},
                          {"curve_points", {{"minor", o.flc->minor}, {"major", o.flc->major}}}};
  }
  if (!w.sections.empty()) {
    nlohmann::json arr = nlohmann::json::array();
    for (const Section& s : w.sections) {
      double len_u = 0, len_d = 0;
      for (const SectionPoint& p : s.points)
        if (p.branch == 0) len_u = p.s_undeformed, len_d = p.s_deformed;
      nlohmann::json e = {{"name", s.name},
                          {"file", s.name + ".csv"},
                          {"definition", s.spec.text},
                          {"points", s.points.size()},
                          {"branches", s.n_branches},
                          {"length_undeformed", len_u},
                          {"length_deformed", len_d}};
      if (s.neck) {
        const NeckResult& n = *s.neck;
        e["neck"] = n.ok ? nlohmann::json{{"limit_major", n.limit_major},     {"limit_minor", n.limit_minor},
                                          {"apex_position", n.apex_position}, {"peak_major", n.peak_major},
                                          {"peak_position", n.peak_position}, {"window_width", n.window_width},
                                          {"fit_points", n.fit_points},       {"fit_rms", n.fit_rms}}
                         : nlohmann::json{{"error", n.message}};
      }
      arr.push_back(std::move(e));
    }
    j["sections"] = arr;
  }
  (void)r;
}
}  // namespace

WrittenResults write_results(io::AtomicOutputDir& out, const GridData& grid, AnalysisResult& result,
                             const OutputOptions& options, const RunInfo& info) {
  const auto t0 = std::chrono::steady_clock::now();
  WrittenResults written;
  const bool mid = options.mid.enabled() && result.method == Method::kSurface;
  if (mid) written.press.mid = mark_mid_strains(result, options.mid);
  if (options.flc) {
    const MarkStrains assessed = assessed_strains(result, written.press.mid, options.measure);
    written.margins = flc_margins(*options.flc, assessed, options.measure);
    std::vector<double> thick(result.points.size(), kNaN);
    for (std::size_t p = 0; p < result.points.size(); ++p) {
      if (!result.points[p].strain) continue;
      if (!mid)
        thick[p] = result.points[p].strain->thickness_change_pct();
      else if (written.press.mid[p])
        thick[p] = 100.0 * (written.press.mid[p]->thickness / options.mid.thickness - 1.0);
    }
    written.press.assessment = assess_marks(*options.flc, assessed, thick, options.measure, options.zones);
    written.press.assessment->curve =
        options.flc_description.empty() ? "table " + options.flc->source : options.flc_description;
    written.press.assessment->strains = mid ? "mid-surface" : "surface (marked face)";
  }
  // Sections before any file: a plane that misses the part fails the run here.
  SectionOptions so;
  so.measure = options.measure;
  if (mid) so.mid = options.mid;
  so.neck = options.neck;
  for (std::size_t k = 0; k < options.sections.size(); ++k) {
    Section sec = cut_section(result, options.sections[k], so, "--section " + std::to_string(k + 1));
    sec.name = "section_" + std::to_string(k + 1);
    written.sections.push_back(std::move(sec));
  }
  const FlcMargins* margins = written.margins ? &*written.margins : nullptr;
  const PressColumns* press = &written.press;
  // The mark table on a second thread while the surfaces are written (independent
  // files and read-only inputs); its exception, if any, is rethrown by get().
  auto csv = std::async(std::launch::async,
                        [&] { write_strains_csv(out.path("strains.csv"), grid, result, options, margins, press); });
  try {
    if (result.method == Method::kSurface) {
      const std::vector<bool> measured = measured_cells(result, 8);  // made once for both surfaces
      for (const bool deformed : {false, true}) {
        io::PolyMesh surface =
            surface_polymesh(result, deformed, 8, mid ? options.mid : MidSurfaceOptions{}, &measured);
        io::write_vtp(out.path(deformed ? "deformed.vtp" : "undeformed.vtp"), surface);
        if (options.keep_surfaces) (deformed ? written.deformed : written.undeformed) = std::move(surface);
      }
      if (options.sample > 0) write_samples_csv(out.path("samples.csv"), result, options);
      for (const Section& sec : written.sections)
        write_section_csv(out.path(sec.name + ".csv"), sec, so, options.units);
      // The fitted surfaces themselves, for `gsa compare` (gsa/surfaces_file.hpp).
      write_surfaces_file(out.path("surfaces.json"), result.mesh, result.undeformed_parameters,
                          result.deformed_parameters, options.units);
    }
  } catch (...) {
    csv.wait();
    throw;
  }
  csv.get();
  result.times.write = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  written.summary = make_summary(grid, result, options, info);
  add_press_summary(written.summary, result, options, written);
  io::write_json(out.path("summary.json"), written.summary);
  return written;
}

}  // namespace sf::gsa
