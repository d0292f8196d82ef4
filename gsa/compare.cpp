#include "gsa/compare.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>
#include <unordered_map>

#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/csv.hpp"
#include "common/io/json.hpp"
#include "common/mesh/projection.hpp"
#include "gsa/analysis.hpp"
#include "gsa/command_options.hpp"
#include "gsa/mark_strains.hpp"
#include "gsa/results_folder.hpp"

namespace sf::gsa {

namespace fs = std::filesystem;

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string angles_text(const std::vector<double>& a) {
  if (a.empty()) return "without fibres";
  std::ostringstream s;
  s << "in fibre mode (";
  for (std::size_t k = 0; k < a.size(); ++k) s << (k ? "," : "") << a[k];
  s << " deg)";
  return s.str();
}

// Values of every field at one material point of one side (NaN where not defined).
struct PointFields {
  bool ok = false;
  std::array<double, kFieldCount> f{};
  Vec3 x = Vec3::Constant(kNaN), X = Vec3::Constant(kNaN);
  Vec3 normal = Vec3::Constant(kNaN);  // unit normal of the deformed surface (x,1 x x,2)
};

class SideFields {
 public:
  SideFields(const CompareSide& side, StrainMeasure measure)
      : side_(&side), pair_(side.surfaces.mesh, side.surfaces.undeformed, side.surfaces.deformed), measure_(measure) {}

  PointFields at(Index element, const Vec2& xi) const {
    PointFields p;
    p.f.fill(kNaN);
    const auto b = basis::BicubicHermite::evaluate(xi, basis::kValues | basis::kFirst);
    const fe::SurfacePoint pu = pair_.undeformed.evaluate3(element, b);
    const fe::SurfacePoint pd = pair_.deformed.evaluate3(element, b);
    p.x = pd.x;
    p.X = pu.x;
    const Vec3 n = pd.dx.col(0).cross(pd.dx.col(1));
    if (n.norm() > 0) p.normal = n.normalized();
    const MarkStrain ms = strain_at(pair_, MeshLocation{element, xi}, side_->fibre_angles);
    if (!ms.strain) return p;
    p.ok = true;
    p.f[static_cast<int>(Field::kMajor)] = principal_strain(*ms.strain, 0, measure_);
    p.f[static_cast<int>(Field::kMinor)] = principal_strain(*ms.strain, 1, measure_);
    p.f[static_cast<int>(Field::kThickness)] = ms.strain->thickness_change_pct();
    if (ms.fibres.size() == 2) {
      p.f[static_cast<int>(Field::kShear)] = ms.shear_angle_deg;
      p.f[static_cast<int>(Field::kStretch1)] = ms.fibres[0].stretch > 0 ? ms.fibres[0].stretch : kNaN;
      p.f[static_cast<int>(Field::kStretch2)] = ms.fibres[1].stretch > 0 ? ms.fibres[1].stretch : kNaN;
    }
    return p;
  }

 private:
  const CompareSide* side_;
  SurfacePair pair_;
  StrainMeasure measure_;
};

// Sign of the simulated normals: +1 when the undeformed blank's mean x,1 x x,2 has z >= 0.
double normal_sign(const FittedSurfaces& s) {
  const fe::SurfaceField f(s.mesh, s.undeformed);
  Vec3 sum = Vec3::Zero();
  for (Index e = 0; e < s.mesh.n_elements(); ++e) {
    const fe::SurfacePoint p = f.evaluate3(e, Vec2(0.5, 0.5), basis::kFirst);
    sum += p.dx.col(0).cross(p.dx.col(1));
  }
  return sum[2] < 0 ? -1.0 : 1.0;
}

double extent_of_surface(const FittedSurfaces& s) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (Index n = 0; n < s.mesh.n_nodes(); ++n) {
    const Vec3 x = s.deformed.row(mesh::SurfaceMesh::dof(n, mesh::kValue)).transpose();
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  return (hi - lo).norm();
}
}  // namespace

bool CompareSide::usable(Index m) const {
  const auto k = static_cast<std::size_t>(m);
  return element[k] >= 0 &&
         (status[k] == kStatusOk || status[k] == kStatusOutlierDeformed || status[k] == kStatusOutlierUndeformed);
}

const char* field_key(Field f) {
  switch (f) {
    case Field::kMajor:
      return "major";
    case Field::kMinor:
      return "minor";
    case Field::kThickness:
      return "thickness_change_pct";
    case Field::kShear:
      return "shear_angle_deg";
    case Field::kStretch1:
      return "fibre1_stretch";
    case Field::kStretch2:
      return "fibre2_stretch";
  }
  return "?";
}

std::string field_title(Field f, StrainMeasure m) {
  switch (f) {
    case Field::kMajor:
      return "Major " + measure_word(m) + " strain";
    case Field::kMinor:
      return "Minor " + measure_word(m) + " strain";
    case Field::kThickness:
      return "Thickness change";
    case Field::kShear:
      return "Fibre shear angle";
    case Field::kStretch1:
      return "Fibre 1 stretch";
    case Field::kStretch2:
      return "Fibre 2 stretch";
  }
  return "?";
}

const char* field_units(Field f) {
  switch (f) {
    case Field::kThickness:
      return "%";
    case Field::kShear:
      return "deg";
    default:
      return "-";
  }
}

CompareSide read_compare_side(const std::string& folder) {
  if (!fs::exists(folder))
    throw InputError(folder + ": no such folder or file; give a results folder of `gsa analyse` or a grid file");
  if (!fs::is_directory(folder)) throw InputError(folder + ": not a folder");
  const fs::path d(folder);
  const std::string surfaces = (d / "surfaces.json").string();
  if (!fs::exists(d / "strains.csv"))
    throw InputError(folder + ": no strains.csv here; give a results folder written by `gsa analyse`, or a grid file");
  if (!fs::exists(surfaces))
    throw InputError(folder +
                     ": no surfaces.json (the fitted surfaces); it is written by `gsa analyse` with the surface "
                     "method since version 0.9: analyse the grid again, or give the grid file instead");
  CompareSide s;
  s.source = folder;
  s.kind = "results folder";
  s.surfaces = read_surfaces_file(surfaces);
  if (fs::exists(d / "summary.json")) s.summary = io::read_json((d / "summary.json").string());
  s.units = s.summary.is_null() ? s.surfaces.units : units_of(s.summary);
  s.fibre_angles = fibre_angles_of(s.summary);
  const io::CsvTable t = io::read_csv((d / "strains.csv").string());
  const std::size_t ci = t.column_index("id"), cs = t.column_index("status"), ce = t.column_index("element"),
                    c1 = t.column_index("xi1"), c2 = t.column_index("xi2");
  const Index ne = s.surfaces.mesh.n_elements();
  for (std::size_t r = 0; r < t.n_rows(); ++r) {
    s.ids.emplace_back(t.cell(r, ci));
    s.status.emplace_back(t.cell(r, cs));
    const double e = t.number(r, ce, true);
    if (std::isfinite(e)) {
      if (e < 0 || e >= static_cast<double>(ne) || e != std::floor(e))
        throw InputError(t.file_name() + ":" + std::to_string(t.line(r)) + ": element " + std::string(t.cell(r, ce)) +
                         " is not an element of surfaces.json (" + std::to_string(ne) +
                         " elements); the files do not belong together: analyse again");
      s.element.push_back(static_cast<Index>(e));
      s.xi.emplace_back(t.number(r, c1), t.number(r, c2));
    } else {
      s.element.push_back(-1);
      s.xi.emplace_back(Vec2::Zero());
    }
  }
  return s;
}

CompareSide analyse_compare_side(const std::string& grid_file, const GridSideOptions& options) {
  if (!fs::exists(grid_file))
    throw InputError(grid_file + ": no such file or folder; give a results folder of `gsa analyse` or a grid file");
  AnalyseFlags flags;
  flags.units = options.units;
  const AnalyseOptions ao = [&] {
    AnalyseOptions o = analyse_options(flags);
    o.fibre_angles = options.fibre_angles;
    return o;
  }();
  const GridData grid = read_grid(grid_file, grid_read_options(flags));
  const AnalysisResult r = analyse(grid, ao);
  return compare_side_from(grid, r, grid_file, options.units);
}

CompareSide compare_side_from(const GridData& grid, const AnalysisResult& r, const std::string& source,
                              const std::string& units) {
  if (r.method != Method::kSurface)
    throw InputError(source + ": gsa compare needs the surface method's fitted surfaces");
  CompareSide s;
  s.source = source;
  s.kind = "grid file";
  s.units = units;
  s.fibre_angles = r.fibre_angles;
  s.surfaces.mesh = r.mesh;
  s.surfaces.undeformed = r.undeformed_parameters;
  s.surfaces.deformed = r.deformed_parameters;
  s.surfaces.mesh.geometry() = r.undeformed_parameters;
  if (!s.surfaces.mesh.has_topology()) s.surfaces.mesh.build_topology();
  s.surfaces.units = units;
  s.ids = grid.ids;
  for (const PointResult& p : r.points) {
    s.status.push_back(p.status);
    s.element.push_back(p.element);
    s.xi.push_back(p.xi);
  }
  s.summary = {
      {"tool", "gsa analyse (inside gsa compare)"},
      {"inputs", {source}},
      {"units", {{"length", units}}},
      {"parameters",
       {{"mesh", {{"grid", r.mesh_layout}, {"elements", r.mesh.n_elements()}}},
        {"gauge_length", r.gauge_length},
        {"mark_spacing", r.mark_spacing},
        {"noise_estimate", r.noise_estimate}}},
      {"fit",
       {{"undeformed", {{"rms_residual", r.rms_undeformed}}}, {"deformed", {{"rms_residual", r.rms_deformed}}}}}};
  if (!r.fibre_angles.empty()) s.summary["parameters"]["fibre_angles_deg"] = r.fibre_angles;
  return s;
}

Statistics statistics_of(const std::vector<double>& values) {
  std::vector<double> v;
  for (double x : values)
    if (std::isfinite(x)) v.push_back(x);
  Statistics s;
  s.n = static_cast<Index>(v.size());
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  double sum = 0, sum2 = 0;
  for (double x : v) sum += x, sum2 += x * x;
  const double n = static_cast<double>(v.size());
  s.mean = sum / n;
  s.rms = std::sqrt(sum2 / n);
  double var = 0;
  for (double x : v) var += (x - s.mean) * (x - s.mean);
  s.std_dev = v.size() > 1 ? std::sqrt(var / (n - 1)) : 0.0;
  s.min = v.front();
  s.max = v.back();
  s.max_abs = std::max(std::abs(s.min), std::abs(s.max));
  // Percentiles by linear interpolation between order statistics.
  auto pct = [&](double p) {
    const double at = p / 100.0 * (n - 1);
    const auto lo = static_cast<std::size_t>(std::floor(at));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (at - static_cast<double>(lo)) * (v[hi] - v[lo]);
  };
  s.p05 = pct(5);
  s.p25 = pct(25);
  s.p50 = pct(50);
  s.p75 = pct(75);
  s.p95 = pct(95);
  return s;
}

CompareResult compare(const CompareSide& m, const CompareSide& s, const CompareOptions& o) {
  if (m.units != s.units)
    throw InputError("the two sides are in different length units: " + m.source + " in " + m.units + ", " + s.source +
                     " in " + s.units + "; analyse both with the same --units");
  const bool fm = !m.fibre_angles.empty(), fsim = !s.fibre_angles.empty();
  bool same_angles = m.fibre_angles.size() == s.fibre_angles.size();
  for (std::size_t k = 0; same_angles && k < m.fibre_angles.size(); ++k)
    same_angles = std::abs(m.fibre_angles[k] - s.fibre_angles[k]) < 1e-9;
  if (fm != fsim || !same_angles)
    throw InputError("mismatched fibre modes: " + m.source + " was analysed " + angles_text(m.fibre_angles) + ", " +
                     s.source + " " + angles_text(s.fibre_angles) +
                     "; analyse both with the same --fibres (or give grid files and gsa compare --fibres)");
  if (m.n_marks() == 0) throw InputError(m.source + ": no marks");
  CompareResult r;
  r.fibre_mode = fm;
  r.measure = o.measure;
  const SideFields mf(m, o.measure), sf(s, o.measure);
  const auto t0 = Clock::now();

  // Shared ids.
  std::unordered_map<std::string, Index> sim_of;
  sim_of.reserve(static_cast<std::size_t>(s.n_marks()));
  for (Index k = 0; k < s.n_marks(); ++k) sim_of.emplace(s.ids[static_cast<std::size_t>(k)], k);
  std::vector<Index> partner(static_cast<std::size_t>(m.n_marks()), -1);
  std::vector<Index> shared;  // measured marks usable on both sides
  std::vector<char> sim_seen(static_cast<std::size_t>(s.n_marks()), 0);
  for (Index k = 0; k < m.n_marks(); ++k) {
    const auto it = sim_of.find(m.ids[static_cast<std::size_t>(k)]);
    if (it == sim_of.end()) continue;
    partner[static_cast<std::size_t>(k)] = it->second;
    sim_seen[static_cast<std::size_t>(it->second)] = 1;
    if (m.usable(k) && s.usable(it->second)) shared.push_back(k);
  }
  r.n_shared = static_cast<Index>(shared.size());
  const bool any_shared_id = std::any_of(partner.begin(), partner.end(), [](Index p) { return p >= 0; });
  if (any_shared_id)
    for (Index k = 0; k < s.n_marks(); ++k)
      if (!sim_seen[static_cast<std::size_t>(k)]) r.simulated_only.push_back(s.ids[static_cast<std::size_t>(k)]);

  // Every measured mark's own fields (its material point on its own surfaces).
  std::vector<PointFields> own(static_cast<std::size_t>(m.n_marks()));
  for (Index k = 0; k < m.n_marks(); ++k)
    if (m.usable(k))
      own[static_cast<std::size_t>(k)] =
          mf.at(m.element[static_cast<std::size_t>(k)], m.xi[static_cast<std::size_t>(k)]);

  // 1. Registration of the deformed parts.
  RegistrationMode mode = o.registration;
  if (mode == RegistrationMode::kAuto)
    mode = r.n_shared >= o.min_shared ? RegistrationMode::kIds : RegistrationMode::kSurface;
  if (mode == RegistrationMode::kIds && r.n_shared < 3)
    throw InputError("--register ids: the two sides share " + std::to_string(r.n_shared) +
                     " analysed marks (same id); need at least 3. Use --register surface");
  if (mode == RegistrationMode::kIds) {
    Points3 from(r.n_shared, 3), to(r.n_shared, 3);
    for (Index q = 0; q < r.n_shared; ++q) {
      const Index k = shared[static_cast<std::size_t>(q)];
      from.row(q) = own[static_cast<std::size_t>(k)].x.transpose();
      const Index j = partner[static_cast<std::size_t>(k)];
      to.row(q) = sf.at(s.element[static_cast<std::size_t>(j)], s.xi[static_cast<std::size_t>(j)]).x.transpose();
    }
    r.registration = fe::robust_rigid_fit(from, to, o.robust);
    r.registration.method = "shared marks (ids)";
    // Per measured mark.
    std::vector<double> d(static_cast<std::size_t>(m.n_marks()), kNaN);
    std::vector<bool> used(static_cast<std::size_t>(m.n_marks()), false);
    for (Index q = 0; q < r.n_shared && r.registration.ok(); ++q) {
      d[static_cast<std::size_t>(shared[static_cast<std::size_t>(q)])] =
          r.registration.distances[static_cast<std::size_t>(q)];
      used[static_cast<std::size_t>(shared[static_cast<std::size_t>(q)])] =
          r.registration.used[static_cast<std::size_t>(q)];
    }
    r.registration.distances = std::move(d);
    r.registration.used = std::move(used);
  } else if (mode == RegistrationMode::kSurface) {
    Points3 pts(m.n_marks(), 3);
    for (Index k = 0; k < m.n_marks(); ++k)
      pts.row(k) = own[static_cast<std::size_t>(k)].x.transpose();  // NaN: skipped
    fe::IcpOptions icp = o.icp;
    icp.robust = o.robust;
    r.registration = fe::register_to_surface(pts, s.surfaces.mesh, s.surfaces.deformed, icp);
  } else {
    r.registration.status = fe::RegistrationReport::Status::kConverged;
    r.registration.method = "none (the sides are in one frame)";
    r.registration.n_points = m.n_marks();
    r.registration.distances.assign(static_cast<std::size_t>(m.n_marks()), kNaN);
    r.registration.used.assign(static_cast<std::size_t>(m.n_marks()), false);
  }
  if (!r.registration.ok())
    throw InputError("cannot register " + m.source + " onto " + s.source + ": " + r.registration.message);
  const fe::RigidTransform& reg = r.registration.transform;

  // 2. Blank map: measured undeformed -> simulated undeformed.
  BlankMap blank = o.blank == BlankMap::kAuto ? BlankMap::kFit : o.blank;
  if (blank == BlankMap::kFit) {
    std::vector<Vec3> from, to;
    if (r.n_shared >= 3) {
      for (Index k : shared) {
        const Index j = partner[static_cast<std::size_t>(k)];
        from.push_back(own[static_cast<std::size_t>(k)].X);
        to.push_back(sf.at(s.element[static_cast<std::size_t>(j)], s.xi[static_cast<std::size_t>(j)]).X);
      }
      r.blank_method = "shared marks (ids)";
    } else if (!r.registration.feet.empty()) {
      for (Index k = 0; k < m.n_marks(); ++k) {
        const auto& f = r.registration.feet[static_cast<std::size_t>(k)];
        if (!r.registration.used[static_cast<std::size_t>(k)] || f.element < 0) continue;
        from.push_back(own[static_cast<std::size_t>(k)].X);
        to.push_back(sf.at(f.element, f.xi).X);
      }
      r.blank_method = "ICP foot points";
    }
    if (from.size() >= 3) {
      Points3 a(static_cast<Index>(from.size()), 3), b(static_cast<Index>(from.size()), 3);
      for (std::size_t q = 0; q < from.size(); ++q) {
        a.row(static_cast<Index>(q)) = from[q].transpose();
        b.row(static_cast<Index>(q)) = to[q].transpose();
      }
      const fe::RegistrationReport br = fe::robust_rigid_fit(a, b, o.robust);
      if (!br.ok()) throw InputError("cannot map the measured blank onto the simulated one: " + br.message);
      r.blank = br.transform;
      r.blank_rms = br.rms;
    } else {
      blank = BlankMap::kSame;
    }
  }
  if (blank == BlankMap::kSame) r.blank_method = "same (identity: the blanks share one frame)";
  r.seconds_registration = seconds_since(t0);
  const auto t1 = Clock::now();

  // 3. + 4. The simulated material point of each measured mark, fields and differences.
  const mesh::SurfaceProjector sim_blank(s.surfaces.mesh, s.surfaces.undeformed);
  const mesh::SurfaceProjector sim_part(s.surfaces.mesh, s.surfaces.deformed);
  const double sign = normal_sign(s.surfaces);
  const double edge_tol = 1e-6 * extent_of_surface(s.surfaces) + 3.0 * r.blank_rms;
  // Material points by projection, in one batch.
  std::vector<Index> by_projection;
  for (Index k = 0; k < m.n_marks(); ++k)
    if (m.usable(k) && partner[static_cast<std::size_t>(k)] < 0) by_projection.push_back(k);
  Points3 q_blank(static_cast<Index>(by_projection.size()), 3);
  for (std::size_t q = 0; q < by_projection.size(); ++q)
    q_blank.row(static_cast<Index>(q)) = r.blank.apply(own[static_cast<std::size_t>(by_projection[q])].X).transpose();
  const std::vector<mesh::Projection> blank_feet = sim_blank.project_all(q_blank);
  std::vector<const mesh::Projection*> blank_foot(static_cast<std::size_t>(m.n_marks()), nullptr);
  for (std::size_t q = 0; q < by_projection.size(); ++q)
    blank_foot[static_cast<std::size_t>(by_projection[q])] = &blank_feet[q];
  Points3 registered(m.n_marks(), 3);
  for (Index k = 0; k < m.n_marks(); ++k) registered.row(k) = reg.apply(own[static_cast<std::size_t>(k)].x).transpose();
  const std::vector<mesh::Projection> part_feet = sim_part.project_all(registered);

  r.marks.resize(static_cast<std::size_t>(m.n_marks()));
  for (Index k = 0; k < m.n_marks(); ++k) {
    const auto kk = static_cast<std::size_t>(k);
    MarkComparison& c = r.marks[kk];
    c.measured.fill(kNaN);
    c.simulated.fill(kNaN);
    c.difference.fill(kNaN);
    c.sim_mark = partner[kk];
    c.registration_distance = r.registration.distances.empty() ? kNaN : r.registration.distances[kk];
    c.registration_used = !r.registration.used.empty() && r.registration.used[kk];
    if (!m.usable(k)) {
      c.reason = "measured: " + m.status[kk];
      continue;
    }
    c.position = own[kk].x;
    c.measured = own[kk].f;
    if (!own[kk].ok) {
      c.reason = "measured: degenerate";
      continue;
    }
    if (any_shared_id && c.sim_mark < 0) {
      c.reason = "simulated: no mark of this id";
      continue;
    }
    if (c.sim_mark >= 0) {
      const auto j = static_cast<std::size_t>(c.sim_mark);
      if (!s.usable(c.sim_mark)) {
        c.reason = "simulated: " + s.status[j];
        continue;
      }
      c.mapping = "id";
      c.sim_element = s.element[j];
      c.sim_xi = s.xi[j];
    } else {
      const mesh::Projection& f = *blank_foot[kk];
      const bool inside = f.status == mesh::Projection::Status::kConverged ||
                          (f.status == mesh::Projection::Status::kOnFreeEdge && f.distance <= edge_tol);
      if (!inside) {
        c.reason = "outside the simulated blank";
        continue;
      }
      c.mapping = "material";
      c.sim_element = f.element;
      c.sim_xi = f.xi;
    }
    const PointFields sp = sf.at(c.sim_element, c.sim_xi);
    if (!sp.ok) {
      c.reason = "simulated: degenerate";
      continue;
    }
    c.matched = true;
    c.simulated = sp.f;
    for (int q = 0; q < kFieldCount; ++q)
      c.difference[static_cast<std::size_t>(q)] =
          c.measured[static_cast<std::size_t>(q)] - c.simulated[static_cast<std::size_t>(q)];
    const Vec3 p = registered.row(k).transpose();
    c.position_difference = (p - sp.x).norm();
    const mesh::Projection& pf = part_feet[kk];
    if (pf.status == mesh::Projection::Status::kConverged) {
      const PointFields foot = sf.at(pf.element, pf.xi);
      if (foot.normal.allFinite()) c.shape_deviation = sign * (p - pf.point).dot(foot.normal);
    }
  }

  // The differences over the measured surface, for pictures and compare.vtp.
  const int sub = std::max(1, o.picture_subdivisions);
  const int np = sub + 1;
  const Index ne = m.surfaces.mesh.n_elements();
  DifferenceSurface& ds = r.surface;
  ds.points.resize(ne * np * np, 3);
  Points3 tess_blank(ne * np * np, 3), tess_part(ne * np * np, 3);
  std::vector<PointFields> tess_own(static_cast<std::size_t>(ne * np * np));
  for (Index e = 0; e < ne; ++e) {
    for (int j = 0; j < np; ++j)
      for (int i = 0; i < np; ++i) {
        const Index pt = (e * np + j) * np + i;
        const PointFields pf = mf.at(e, Vec2(double(i) / sub, double(j) / sub));
        ds.points.row(pt) = pf.x.transpose();
        tess_blank.row(pt) = r.blank.apply(pf.X).transpose();
        tess_part.row(pt) = reg.apply(pf.x).transpose();
        tess_own[static_cast<std::size_t>(pt)] = pf;
      }
    for (int j = 0; j < sub; ++j)
      for (int i = 0; i < sub; ++i) {
        const Index a = (e * np + j) * np + i;
        ds.polygons.push_back({a, a + 1, a + np + 1, a + np});
      }
  }
  const std::vector<mesh::Projection> tb = sim_blank.project_all(tess_blank);
  const std::vector<mesh::Projection> tp = sim_part.project_all(tess_part);
  for (auto& v : ds.difference) v.assign(static_cast<std::size_t>(ds.points.rows()), kNaN);
  ds.shape_deviation.assign(static_cast<std::size_t>(ds.points.rows()), kNaN);
  ds.position_difference.assign(static_cast<std::size_t>(ds.points.rows()), kNaN);
  for (Index pt = 0; pt < ds.points.rows(); ++pt) {
    const auto p = static_cast<std::size_t>(pt);
    const PointFields& mine = tess_own[p];
    if (!mine.ok) continue;
    const bool inside = tb[p].status == mesh::Projection::Status::kConverged ||
                        (tb[p].status == mesh::Projection::Status::kOnFreeEdge && tb[p].distance <= edge_tol);
    if (!inside) continue;
    const PointFields other = sf.at(tb[p].element, tb[p].xi);
    if (!other.ok) continue;
    for (int q = 0; q < kFieldCount; ++q)
      ds.difference[static_cast<std::size_t>(q)][p] =
          mine.f[static_cast<std::size_t>(q)] - other.f[static_cast<std::size_t>(q)];
    ds.position_difference[p] = (tess_part.row(pt).transpose() - other.x).norm();
    if (tp[p].status == mesh::Projection::Status::kConverged) {
      const PointFields foot = sf.at(tp[p].element, tp[p].xi);
      if (foot.normal.allFinite())
        ds.shape_deviation[p] = sign * (tess_part.row(pt).transpose() - tp[p].point).dot(foot.normal);
    }
  }
  r.seconds_mapping = seconds_since(t1);
  return r;
}

namespace {
nlohmann::json stats_json(const Statistics& s) {
  if (s.n == 0) return {{"n", 0}};
  return {{"n", s.n},     {"mean", s.mean}, {"rms", s.rms},         {"std", s.std_dev},
          {"min", s.min}, {"max", s.max},   {"max_abs", s.max_abs}, {"p05", s.p05},
          {"p25", s.p25}, {"p50", s.p50},   {"p75", s.p75},         {"p95", s.p95}};
}

nlohmann::json side_json(const CompareSide& side) {
  nlohmann::json j = {{"source", side.source}, {"kind", side.kind}, {"marks", side.n_marks()}};
  Index usable = 0;
  for (Index k = 0; k < side.n_marks(); ++k) usable += side.usable(k) ? 1 : 0;
  j["marks_analysed"] = usable;
  j["elements"] = side.surfaces.mesh.n_elements();
  if (side.summary.is_object()) {
    if (side.summary.contains("inputs")) j["inputs"] = side.summary["inputs"];
    if (side.summary.contains("fit")) j["fit"] = side.summary["fit"];
  }
  return j;
}
}  // namespace

nlohmann::json compare_summary(const CompareSide& m, const CompareSide& s, const CompareResult& r,
                               const std::string& command_line) {
  nlohmann::json j;
  j["tool"] = "gsa compare";
  j["version"] = SF_VERSION;
  j["command_line"] = command_line;
  j["measured"] = side_json(m);
  j["simulated"] = side_json(s);
  j["units"] = {{"length", m.units},
                {"strain", "dimensionless, " + measure_name(r.measure)},
                {"thickness_change", "percent"},
                {"angles", "degrees"}};
  j["sign"] =
      "difference = measured - simulated; shape_deviation > 0: the measured part lies on the side of the "
      "simulated surface that the blank's +Z face looks to";
  const fe::RegistrationReport& g = r.registration;
  const Eigen::AngleAxisd aa(g.transform.rotation);
  nlohmann::json rot = nlohmann::json::array();
  for (int a = 0; a < 3; ++a)
    rot.push_back({g.transform.rotation(a, 0), g.transform.rotation(a, 1), g.transform.rotation(a, 2)});
  const Vec3 axis = g.transform.axis();
  j["registration"] = {
      {"method", g.method},
      {"maps", "measured onto simulated: x_sim = R x_measured + t"},
      {"status", fe::to_string(g.status)},
      {"message", g.message},
      {"rotation_matrix", rot},
      {"rotation_deg", g.transform.angle_deg()},
      {"rotation_axis", {axis[0], axis[1], axis[2]}},
      {"translation", {g.transform.translation[0], g.transform.translation[1], g.transform.translation[2]}},
      {"rms_distance", g.rms},
      {"rms_distance_all", g.rms_all},
      {"robust_scale", g.scale},
      {"points", g.n_points},
      {"points_used", g.n_used},
      {"iterations", g.iterations}};
  if (!g.start.empty()) j["registration"]["start"] = g.start;
  const Vec3 baxis = r.blank.axis();
  j["blank_map"] = {{"method", r.blank_method},
                    {"maps", "measured undeformed onto simulated undeformed (material coordinates)"},
                    {"rotation_deg", r.blank.angle_deg()},
                    {"rotation_axis", {baxis[0], baxis[1], baxis[2]}},
                    {"translation", {r.blank.translation[0], r.blank.translation[1], r.blank.translation[2]}},
                    {"rms_distance", r.blank_rms}};
  Index matched = 0, by_id = 0;
  nlohmann::json unmatched = nlohmann::json::array();
  std::map<std::string, Index> reasons;
  for (std::size_t k = 0; k < r.marks.size(); ++k) {
    const MarkComparison& c = r.marks[k];
    if (c.matched) {
      ++matched;
      by_id += c.mapping == "id" ? 1 : 0;
    } else {
      ++reasons[c.reason];
      unmatched.push_back({{"id", m.ids[k]}, {"reason", c.reason}});
    }
  }
  j["counts"] = {{"measured_marks", m.n_marks()},
                 {"simulated_marks", s.n_marks()},
                 {"shared_ids_analysed", r.n_shared},
                 {"matched", matched},
                 {"matched_by_id", by_id},
                 {"matched_by_material_point", matched - by_id},
                 {"unmatched", static_cast<Index>(unmatched.size())},
                 {"unmatched_by_reason", reasons},
                 {"simulated_only", static_cast<Index>(r.simulated_only.size())}};
  j["unmatched"] = unmatched;
  j["simulated_only"] = r.simulated_only;
  nlohmann::json stats;
  for (int q = 0; q < kFieldCount; ++q) {
    if (!r.fibre_mode && q >= static_cast<int>(Field::kShear)) continue;
    std::vector<double> v;
    for (const auto& c : r.marks) v.push_back(c.difference[static_cast<std::size_t>(q)]);
    stats[field_key(static_cast<Field>(q))] = stats_json(statistics_of(v));
    stats[field_key(static_cast<Field>(q))]["units"] = field_units(static_cast<Field>(q));
  }
  std::vector<double> sd, pd;
  for (const auto& c : r.marks) sd.push_back(c.shape_deviation), pd.push_back(c.position_difference);
  stats["shape_deviation"] = stats_json(statistics_of(sd));
  stats["shape_deviation"]["units"] = m.units;
  stats["position_difference"] = stats_json(statistics_of(pd));
  stats["position_difference"]["units"] = m.units;
  j["statistics"] = stats;
  j["timings_s"] = {{"registration", r.seconds_registration}, {"mapping", r.seconds_mapping}};
  return j;
}

void write_differences_csv(const std::string& path, const CompareSide& m, const CompareResult& r) {
  std::vector<std::string> cols = {"id",      "status",  "reason", "mapping", "sim_element",
                                   "sim_xi1", "sim_xi2", "x",      "y",       "z"};
  std::vector<int> fields = {0, 1, 2};
  if (r.fibre_mode) fields = {0, 1, 2, 3, 4, 5};
  for (int q : fields)
    for (const char* side : {"_measured", "_simulated", "_difference"})
      cols.push_back(std::string(field_key(static_cast<Field>(q))) + side);
  for (const char* c : {"shape_deviation", "position_difference", "registration_distance", "registration_used"})
    cols.emplace_back(c);
  io::write_file_atomic(path, [&](std::ostream& os) {
    os << "# gsa compare: one row per measured mark; difference = measured - simulated; strains "
       << measure_name(r.measure) << " (dimensionless), thickness change in %, shear angle in degrees; x,y,z the "
       << "measured mark on its fitted deformed surface (" << m.units << "); shape_deviation, position_difference "
       << "and registration_distance in " << m.units << "; status unmatched rows say why in reason\n";
    io::CsvWriter w(os, cols);
    for (std::size_t k = 0; k < r.marks.size(); ++k) {
      const MarkComparison& c = r.marks[k];
      w.begin_row().add(m.ids[k]).add(c.matched ? "matched" : "unmatched").add(c.reason).add(c.mapping);
      if (c.sim_element >= 0)
        w.add(c.sim_element).add(c.sim_xi[0]).add(c.sim_xi[1]);
      else
        w.add(kNaN).add(kNaN).add(kNaN);
      w.add(c.position[0]).add(c.position[1]).add(c.position[2]);
      for (int q : fields) {
        const auto qq = static_cast<std::size_t>(q);
        w.add(c.matched ? c.measured[qq] : kNaN).add(c.matched ? c.simulated[qq] : kNaN).add(c.difference[qq]);
      }
      w.add(c.shape_deviation).add(c.position_difference).add(c.registration_distance);
      w.add(c.registration_used ? 1 : 0);
      w.end_row();
    }
  });
}

}  // namespace sf::gsa
