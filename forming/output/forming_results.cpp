#include "forming/output/forming_results.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/core/error.hpp"
#include "common/io/csv.hpp"
#include "forming/output/forming_fields.hpp"

namespace sf::forming {
namespace {

std::string num(double v) {
  if (!std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

struct Range {
  double lo = 1e300, hi = -1e300, abs_max = 0.0;
  bool any = false;
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    abs_max = std::max(abs_max, std::abs(v));
    any = true;
  }
};

}  // namespace

nlohmann::json forming_summary(const FormingCase& spec, const Model& model, const VecX& x, int samples) {
  const FormingFields fields(model, x);
  nlohmann::json plies = nlohmann::json::array();
  for (int b = 0; b < model.n_bodies(); ++b) {
    Range stretch, angle, shear, trellis, thick;
    const PlyMesh& ply = model.ply(b);
    for (Index e = 0; e < ply.n_elements(); ++e)
      for (int j = 0; j < samples; ++j)
        for (int i = 0; i < samples; ++i) {
          const PlyPointFields f = fields.at(b, e, Vec3((i + 0.5) / samples, (j + 0.5) / samples, 0.5));
          stretch.add(f.fibre_stretch);
          angle.add(f.fibre_angle_change_deg);
          shear.add(f.ply_shear_deg);
          trellis.add(f.trellis_shear_deg);
          thick.add(f.thickness);
        }
    const WrinkleResult w = fields.wrinkles(b, samples);
    const std::string name = static_cast<std::size_t>(b) < spec.plies.size() ? spec.plies[b].name : std::to_string(b);
    const int p = fields.partner(b);
    nlohmann::json j = {
        {"ply", name},
        {"fibre_reinforced", fields.fibre_reinforced(b)},
        {"fibre_stretch", {{"min", stretch.lo}, {"max", stretch.hi}}},
        {"fibre_angle_change_deg", {{"min", angle.lo}, {"max", angle.hi}}},
        {"ply_shear_angle_deg", {{"min", shear.lo}, {"max", shear.hi}, {"max_abs", shear.abs_max}}},
        {"thickness_mm", {{"reference", ply.thickness()}, {"min", thick.lo}, {"max", thick.hi}}},
        {"wrinkling",
         {{"amplitude_mm", w.amplitude},
          {"rms_mm", w.rms},
          {"wavelength_mm", finite_or_null(w.wavelength)},
          {"smoothing_radius_mm", w.radius}}},
    };
    if (p >= 0) {
      j["trellis_partner"] = static_cast<std::size_t>(p) < spec.plies.size() ? spec.plies[p].name : std::to_string(p);
      j["trellis_shear_angle_deg"] =
          trellis.any ? nlohmann::json{{"min", trellis.lo}, {"max", trellis.hi}, {"max_abs", trellis.abs_max}}
                      : nlohmann::json();
    }
    plies.push_back(j);
  }
  return {{"plies", plies},
          {"definitions", "docs/forming.md, Forming results: mid-thickness values at " + std::to_string(samples) +
                              " x " + std::to_string(samples) + " points per brick"}};
}

Vec3 part_centre(const FormingCase& spec, const Model& model) {
  Eigen::AlignedBox3d box;
  for (int b = 0; b < model.n_bodies(); ++b) {
    const MatX& R = model.ply(b).reference();
    for (Index s = 0; s < model.ply(b).n_nodes(); ++s) box.extend(Vec3(R.row(4 * s).transpose()));
  }
  Vec3 c = box.center();
  for (const CaseBoundary& bc : spec.boundaries) {
    if (bc.kind != CaseBoundary::Kind::kSymmetry) continue;
    if (bc.side == PlySide::kX0) c[0] = box.min()[0];
    if (bc.side == PlySide::kY0) c[1] = box.min()[1];
  }
  return c;
}

std::string profiles_csv(const FormingCase& spec, const Model& model, const VecX& x) {
  const FormingFields fields(model, x);
  const Vec3 c = part_centre(spec, model);
  std::ostringstream os;
  os << "direction_deg,ply,s_mm,X_mm,Y_mm,x_mm,y_mm,z_mm,draw_in_mm,thickness_mm,trellis_shear_deg,ply_shear_deg,"
        "fibre_angle_change_deg,fibre_stretch\n";
  for (const double deg : {0.0, 45.0, 90.0}) {
    const double r = deg * 3.14159265358979323846 / 180.0;
    const Vec3 d(std::cos(r), std::sin(r), 0.0);
    for (int b = 0; b < model.n_bodies(); ++b) {
      const PlyMesh& ply = model.ply(b);
      const Vec3 n = fields.reference_normal(b);
      // The line at the ply's mid-plane level, sampled every quarter element to its edge.
      const MatX& R = ply.reference();
      double level = 0.0;
      for (Index s = 0; s < ply.n_nodes(); ++s) level += R(4 * s, 2);
      level /= static_cast<double>(ply.n_nodes());
      const double h = 0.25 * fields.element_size(b);
      const std::string name = static_cast<std::size_t>(b) < spec.plies.size() ? spec.plies[b].name : std::to_string(b);
      (void)n;
      for (int k = 0;; ++k) {
        const double s = k * h;
        Vec3 X = c + s * d;
        X[2] = level;
        Index e = -1;
        Vec2 xi;
        if (!fields.locate_reference(b, X, e, xi)) {
          if (k == 0) continue;  // the centre is off this ply: try a little further
          break;
        }
        if (k > 100000) break;
        const PlyPointFields f = fields.at(b, e, Vec3(xi[0], xi[1], 0.5));
        const Vec3 plan = f.x - c;
        const double draw_in = s - (plan[0] * d[0] + plan[1] * d[1]);
        os << num(deg) << ',' << name << ',' << num(s) << ',' << num(f.X[0]) << ',' << num(f.X[1]) << ',' << num(f.x[0])
           << ',' << num(f.x[1]) << ',' << num(f.x[2]) << ',' << num(draw_in) << ',' << num(f.thickness) << ','
           << num(f.trellis_shear_deg) << ',' << num(f.ply_shear_deg) << ',' << num(f.fibre_angle_change_deg) << ','
           << num(f.fibre_stretch) << '\n';
      }
    }
  }
  return os.str();
}

std::string tool_force_csv(const std::string& history_text, const std::string& name, double process_time) {
  const io::CsvTable t = io::read_csv_string(history_text, name);
  const auto col = [&](const std::string& c) -> std::size_t {
    const auto i = t.find_column(c);
    if (!i) throw Error(name + ": no column '" + c + "' (expected the history.csv of simform run)");
    return *i;
  };
  // The tools: every prefix P with P_ux and P_fz columns other than "tool" (the edge).
  std::vector<std::string> tools;
  for (std::size_t i = 0; i < t.names().size(); ++i) {
    const std::string& h = t.names()[i];
    if (h.size() > 3 && h.compare(h.size() - 3, 3, "_ux") == 0 && h != "tool_ux")
      tools.push_back(h.substr(0, h.size() - 3));
  }
  const bool edge = tools.empty();
  if (edge) tools.push_back("tool");
  const std::size_t rows = t.n_rows();
  const std::size_t c_step = col("step"), c_lf = col("load_factor");
  const auto c_time = t.find_column("time");
  std::ostringstream os;
  os << "step,time_s,load_factor";
  for (const std::string& tool : tools) {
    const std::string p = edge ? "edge" : tool;
    os << ',' << p << "_stroke_mm," << p << "_force_N," << p << "_fx_N," << p << "_fy_N," << p << "_fz_N";
  }
  os << '\n';
  std::vector<Vec3> dir;
  for (const std::string& tool : tools) {
    Vec3 d = Vec3::UnitZ();
    if (rows > 0) {
      const Vec3 u(t.number(rows - 1, col(tool + "_ux")), t.number(rows - 1, col(tool + "_uy")),
                   t.number(rows - 1, col(tool + "_uz")));
      if (u.norm() > 0.0) d = u.normalized();
    }
    dir.push_back(d);
  }
  for (std::size_t r = 0; r < rows; ++r) {
    const double lf = t.number(r, c_lf);
    os << num(t.number(r, c_step)) << ',' << num(c_time ? t.number(r, *c_time) : lf * process_time) << ',' << num(lf);
    for (std::size_t k = 0; k < tools.size(); ++k) {
      const std::string& tool = tools[k];
      const Vec3 u(t.number(r, col(tool + "_ux")), t.number(r, col(tool + "_uy")), t.number(r, col(tool + "_uz")));
      const Vec3 f(t.number(r, col(tool + "_fx")), t.number(r, col(tool + "_fy")), t.number(r, col(tool + "_fz")));
      const double force = edge ? f.dot(dir[k]) : -f.dot(dir[k]);
      os << ',' << num(u.dot(dir[k])) << ',' << num(force) << ',' << num(f[0]) << ',' << num(f[1]) << ',' << num(f[2]);
    }
    os << '\n';
  }
  return os.str();
}

}  // namespace sf::forming
