#include "forming/output/frames.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "forming/contact/surface_contact.hpp"
#include "forming/contact/tool_contact.hpp"
#include "forming/material/material.hpp"
#include "forming/output/forming_fields.hpp"
#include "forming/output/sampling.hpp"

namespace sf::forming {
namespace {

// The contact records of one slave face on its n x n Gauss grid, for interpolation onto
// the tessellation's points of that face.
struct FaceContactGrid {
  BrickFace face = BrickFace::kTop;
  int s_dir = 0, t_dir = 1;                      // brick xi directions of the face's s and t
  double fixed_at = 0.0;                         // the third xi direction's value on the face (0 or 1)
  std::vector<double> abscissae;                 // the grid's 1-D points in [0, 1], ascending
  std::vector<const ContactPointRecord*> point;  // n x n, index i_s + n i_t
};

// Ascending interval and weight of u on the abscissae: u = (1 - w) g_i + w g_(i+1),
// clamped to the end points outside them.
std::pair<int, double> locate(const std::vector<double>& g, double u) {
  const int n = static_cast<int>(g.size());
  if (n == 1 || u <= g.front()) return {0, 0.0};
  if (u >= g.back()) return {n - 2, 1.0};
  int i = 0;
  while (i + 2 < n && u > g[static_cast<std::size_t>(i + 1)]) ++i;
  const double a = g[static_cast<std::size_t>(i)], b = g[static_cast<std::size_t>(i + 1)];
  return {i, (u - a) / (b - a)};
}

struct ContactFieldValue {
  double pressure = 0.0;
  double gap = std::nan("");
  Vec3 slip = Vec3::Zero(), slip_rate = Vec3::Zero();
};

// Bilinear interpolation of the face's records at face point (s, t) (pressure and slip
// rate where the points have a partner; the gap only where all four do).
ContactFieldValue interpolate(const FaceContactGrid& g, double s, double t) {
  const int n = static_cast<int>(g.abscissae.size());
  const auto [i, u] = locate(g.abscissae, s);
  const auto [j, v] = locate(g.abscissae, t);
  ContactFieldValue out;
  double gap = 0.0;
  bool all = true;
  for (int b = 0; b < 2; ++b)
    for (int a = 0; a < 2; ++a) {
      const int ia = std::min(i + a, n - 1), jb = std::min(j + b, n - 1);
      const double w = (a ? u : 1.0 - u) * (b ? v : 1.0 - v);
      const ContactPointRecord& r = *g.point[static_cast<std::size_t>(ia + n * jb)];
      out.pressure += w * r.pressure;
      out.slip += w * r.slip;
      out.slip_rate += w * r.slip_rate;
      if (r.partner)
        gap += w * r.gap;
      else if (w > 0.0)
        all = false;
    }
  if (all) out.gap = gap;
  return out;
}

// Per body and element, the contact grids of its slave faces (every SurfaceContact).
struct ContactFields {
  std::vector<std::vector<ContactPointRecord>> records;          // per interaction
  std::vector<std::vector<std::vector<FaceContactGrid>>> grids;  // [body][element]
};

ContactFields collect_contact_fields(const Model& model, const VecX& x, const InteractionContext& context) {
  ContactFields out;
  out.grids.resize(static_cast<std::size_t>(model.n_bodies()));
  for (int b = 0; b < model.n_bodies(); ++b) out.grids[static_cast<std::size_t>(b)].resize(model.ply(b).n_elements());
  for (int i = 0; i < model.n_interactions(); ++i) {
    const auto* sc = dynamic_cast<const SurfaceContact*>(&model.interaction(i));
    if (!sc) continue;
    out.records.push_back(sc->sample(x, context));
  }
  std::size_t k = 0;
  for (int i = 0; i < model.n_interactions(); ++i) {
    const auto* sc = dynamic_cast<const SurfaceContact*>(&model.interaction(i));
    if (!sc) continue;
    const std::vector<ContactPointRecord>& rec = out.records[k++];
    const ContactSurface& surface = sc->slave();
    const int n = sc->options().points, per_face = sc->points_per_face();
    for (Index f = 0; f < surface.n_faces(); ++f) {
      FaceContactGrid g;
      g.face = surface.face(f).face;
      const FaceBasis& fb = surface.basis(f);
      const Vec3 o = fb.xi(0, 0), ds = fb.xi(1, 0) - o, dt = fb.xi(0, 1) - o;
      for (int c = 0; c < 3; ++c) {
        if (ds[c] != 0.0) g.s_dir = c;
        if (dt[c] != 0.0) g.t_dir = c;
      }
      g.fixed_at = o[3 - g.s_dir - g.t_dir];
      const std::size_t first = static_cast<std::size_t>(f * per_face);
      for (int q = 0; q < per_face; ++q) g.abscissae.push_back(rec[first + static_cast<std::size_t>(q)].st[0]);
      std::sort(g.abscissae.begin(), g.abscissae.end());
      g.abscissae.erase(std::unique(g.abscissae.begin(), g.abscissae.end(),
                                    [](double a, double b) { return std::abs(a - b) < 1e-12; }),
                        g.abscissae.end());
      if (static_cast<int>(g.abscissae.size()) != n) continue;  // not a tensor grid: leave the face out
      g.point.assign(static_cast<std::size_t>(per_face), nullptr);
      const auto index = [&](double u) {
        return static_cast<int>(
            std::min_element(g.abscissae.begin(), g.abscissae.end(),
                             [&](double a, double b) { return std::abs(a - u) < std::abs(b - u); }) -
            g.abscissae.begin());
      };
      for (int q = 0; q < per_face; ++q) {
        const ContactPointRecord& r = rec[first + static_cast<std::size_t>(q)];
        g.point[static_cast<std::size_t>(index(r.st[0]) + n * index(r.st[1]))] = &r;
      }
      out.grids[static_cast<std::size_t>(surface.body())][static_cast<std::size_t>(surface.face(f).element)].push_back(
          std::move(g));
    }
  }
  return out;
}

}  // namespace

io::VolumeMesh tessellate(const Model& model, const VecX& x, int samples_inplane, int samples_thickness,
                          const InteractionContext* context) {
  ContactFields contact;
  bool with_contact = false;
  if (context) {
    for (int i = 0; i < model.n_interactions() && !with_contact; ++i)
      with_contact = dynamic_cast<const SurfaceContact*>(&model.interaction(i)) != nullptr;
    if (with_contact) contact = collect_contact_fields(model, x, *context);
  }
  std::vector<double> c_pressure, c_gap, c_slip, c_rate;
  const int ns = samples_inplane, nt = samples_thickness;
  io::VolumeMesh mesh;
  std::vector<Vec3> points;
  std::vector<double> disp, stress, fibre, stretch, body_id, pressure, tension;
  // Forming results per column of cells (mid-thickness; forming_fields.hpp).
  std::vector<double> angle_change, ply_shear, trellis, thickness, waviness;
  const FormingFields forming(model, x);
  const bool constrained = model.any_constrained();
  for (int b = 0; b < model.n_bodies(); ++b) {
    const WrinkleResult wrinkle = forming.wrinkles(b, ns);
    const PlyMesh& ply = model.ply(b);
    const Material& material = model.material(b);
    // Element pressure and fibre tension of a constrained ply (sigma gains -p I + T/J a a).
    const std::vector<Model::ConstraintState> cs = model.constraint_state(b, x);
    const Vec3 a0 = ply.fibre_direction();
    const MatX xb = PlyMesh::unflatten(x.segment(model.offset(b), ply.n_dofs()));
    for (Index e = 0; e < ply.n_elements(); ++e) {
      const BrickParams Xe = ply.element_parameters(e, ply.reference());
      const BrickParams xe = ply.element_parameters(e, xb);
      const Index first = static_cast<Index>(points.size());
      for (int k = 0; k <= nt; ++k)
        for (int j = 0; j <= ns; ++j)
          for (int i = 0; i <= ns; ++i) {
            const Vec3 xi(double(i) / ns, double(j) / ns, double(k) / nt);
            const BrickPoint s = sample_brick(Xe, xe, xi);
            points.push_back(s.x);
            for (int c = 0; c < 3; ++c) disp.push_back(s.x[c] - s.X[c]);
            if (!with_contact) continue;
            // On a slave face: the face's contact fields (the pair with the highest pressure).
            ContactFieldValue best;
            bool found = false;
            for (const FaceContactGrid& g : contact.grids[static_cast<std::size_t>(b)][static_cast<std::size_t>(e)]) {
              const int fixed = 3 - g.s_dir - g.t_dir;
              if (std::abs(xi[fixed] - g.fixed_at) > 1e-12) continue;
              const ContactFieldValue v = interpolate(g, xi[g.s_dir], xi[g.t_dir]);
              if (!found || v.pressure > best.pressure) best = v;
              found = true;
            }
            c_pressure.push_back(best.pressure);
            c_gap.push_back(best.gap);
            for (int c = 0; c < 3; ++c) {
              c_slip.push_back(best.slip[c]);
              c_rate.push_back(best.slip_rate[c]);
            }
          }
      auto pid = [&](int i, int j, int k) { return first + (static_cast<Index>(k) * (ns + 1) + j) * (ns + 1) + i; };
      std::vector<PlyPointFields> column;
      for (int j = 0; j < ns; ++j)
        for (int i = 0; i < ns; ++i) column.push_back(forming.at(b, e, Vec3((i + 0.5) / ns, (j + 0.5) / ns, 0.5)));
      for (int k = 0; k < nt; ++k)
        for (int j = 0; j < ns; ++j)
          for (int i = 0; i < ns; ++i) {
            mesh.add_cell(io::CellType::kHexahedron,
                          {pid(i, j, k), pid(i + 1, j, k), pid(i + 1, j + 1, k), pid(i, j + 1, k), pid(i, j, k + 1),
                           pid(i + 1, j, k + 1), pid(i + 1, j + 1, k + 1), pid(i, j + 1, k + 1)});
            const Vec3 xi((i + 0.5) / ns, (j + 0.5) / ns, (k + 0.5) / nt);
            const BrickPoint s = sample_brick(Xe, xe, xi);
            const Mat3 C = s.F.transpose() * s.F;
            Mat3 sigma = Mat3::Constant(std::nan(""));
            if (s.F.determinant() > 0.0) sigma = cauchy_stress(s.F, material.evaluate(C, false).stress);
            const Vec3 a = s.F * a0;
            double p_e = 0.0, t_e = 0.0;
            if (!cs.empty()) {
              const ConstraintTerms& ct = model.constraints(b);
              p_e = ct.incompressible ? cs[static_cast<std::size_t>(e)].p_eff : 0.0;
              t_e = ct.inextensible ? cs[static_cast<std::size_t>(e)].T_eff : 0.0;
              sigma += -p_e * Mat3::Identity() + (t_e / s.F.determinant()) * a * a.transpose();
            }
            if (constrained) {
              pressure.push_back(p_e);
              tension.push_back(t_e);
            }
            const Vec6 v = voigt_stress(sigma);
            for (int c = 0; c < 6; ++c) stress.push_back(v[c]);
            const double lam = a.norm();
            for (int c = 0; c < 3; ++c) fibre.push_back(lam > 0.0 ? a[c] / lam : 0.0);
            stretch.push_back(lam);
            body_id.push_back(b);
            const PlyPointFields& f = column[static_cast<std::size_t>(j * ns + i)];
            angle_change.push_back(f.fibre_angle_change_deg);
            ply_shear.push_back(f.ply_shear_deg);
            trellis.push_back(f.trellis_shear_deg);
            thickness.push_back(f.thickness);
            waviness.push_back(wrinkle.deviation[static_cast<std::size_t>((e * ns + j) * ns + i)]);
          }
    }
  }
  mesh.points.resize(static_cast<Index>(points.size()), 3);
  for (std::size_t p = 0; p < points.size(); ++p) mesh.points.row(static_cast<Index>(p)) = points[p].transpose();
  mesh.point_data.push_back({"displacement", 3, std::move(disp)});
  if (with_contact) {
    mesh.point_data.push_back({"contact_pressure", 1, std::move(c_pressure)});
    mesh.point_data.push_back({"contact_gap", 1, std::move(c_gap)});
    mesh.point_data.push_back({"contact_slip", 3, std::move(c_slip)});
    mesh.point_data.push_back({"contact_slip_rate", 3, std::move(c_rate)});
  }
  mesh.cell_data.push_back({"cauchy_stress", 6, std::move(stress)});
  mesh.cell_data.push_back({"fibre_direction", 3, std::move(fibre)});
  mesh.cell_data.push_back({"fibre_stretch", 1, std::move(stretch)});
  mesh.cell_data.push_back({"ply", 1, std::move(body_id)});
  mesh.cell_data.push_back({"fibre_angle_change", 1, std::move(angle_change)});
  mesh.cell_data.push_back({"ply_shear_angle", 1, std::move(ply_shear)});
  mesh.cell_data.push_back({"trellis_shear_angle", 1, std::move(trellis)});
  mesh.cell_data.push_back({"thickness", 1, std::move(thickness)});
  mesh.cell_data.push_back({"waviness", 1, std::move(waviness)});
  if (constrained) {
    mesh.cell_data.push_back({"pressure", 1, std::move(pressure)});
    mesh.cell_data.push_back({"fibre_tension", 1, std::move(tension)});
  }
  return mesh;
}

std::string step_file_name(int k) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "steps/step_%04d.vtu", k);
  return buf;
}

void FrameSeries::write(const io::AtomicOutputDir& out, int k, double lambda, const VecX& x,
                        const InteractionContext* context) {
  const std::string name = step_file_name(k);
  io::write_vtu(out.path(name), tessellate(model_, x, samples_inplane_, samples_thickness_, context));
  frames_.erase(std::remove_if(frames_.begin(), frames_.end(), [&](const auto& f) { return f.second == name; }),
                frames_.end());
  frames_.emplace_back(lambda, name);
  // The parts of a frame of the same step written before (a restart) are replaced too.
  char number[16];
  std::snprintf(number, sizeof number, "_%04d.vtu", k);
  parts_.erase(std::remove_if(parts_.begin(), parts_.end(),
                              [&](const io::PvdDataSet& p) {
                                return p.file.size() > 16 && p.file.compare(p.file.size() - 9, 9, number) == 0;
                              }),
               parts_.end());
  if (context) write_contact_parts(out, k, lambda, x, *context);
}

void FrameSeries::write_contact_parts(const io::AtomicOutputDir& out, int k, double lambda, const VecX& x,
                                      const InteractionContext& context) {
  char number[16];
  std::snprintf(number, sizeof number, "%04d", k);
  // The plies' reference box, enlarged: the region tools are drawn over.
  const VecX X = model_.reference_positions();
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (Index i = 0; i + 2 < X.size(); i += 3) {
    // Value dofs and derivative dofs share the layout; derivatives are small lengths too,
    // so the box of all triples is a (loose) box of the plies.
    lo = lo.cwiseMin(X.segment<3>(i));
    hi = hi.cwiseMax(X.segment<3>(i));
  }
  const Vec3 pad = Vec3::Constant(0.1 * (hi - lo).norm());
  io::VolumeMesh points;
  std::vector<double> pressure, gap, slip, slip_rate, shear, pair;
  std::vector<std::string> tools_done;
  int part = 1;
  for (int i = 0; i < model_.n_interactions(); ++i) {
    const auto* sc = dynamic_cast<const SurfaceContact*>(&model_.interaction(i));
    if (!sc) continue;
    for (const ContactPointRecord& r : sc->sample(x, context)) {
      const Index id = points.points.rows();
      points.points.conservativeResize(id + 1, 3);
      points.points.row(id) = r.position.transpose();
      points.add_cell(io::CellType::kVertex, {id});
      pressure.push_back(r.pressure);
      gap.push_back(r.partner ? r.gap : 0.0);
      for (int c = 0; c < 3; ++c) {
        slip.push_back(r.slip[c]);
        slip_rate.push_back(r.slip_rate[c]);
        shear.push_back(r.shear[c]);
      }
      pair.push_back(i);
    }
    const auto* tc = dynamic_cast<const ToolContact*>(sc);
    if (!tc || std::find(tools_done.begin(), tools_done.end(), tc->tool().name) != tools_done.end()) continue;
    tools_done.push_back(tc->tool().name);
    const ToolTessellation t = tc->tool().shape->tessellate(lo - pad, hi + pad);
    const Vec3 d = tc->tool().motion.displacement(context.time);
    io::VolumeMesh surface;
    surface.points.resize(t.points.rows(), 3);
    for (Index p = 0; p < t.points.rows(); ++p) surface.points.row(p) = t.points.row(p) + d.transpose();
    for (const auto& tri : t.triangles) surface.add_cell(io::CellType::kTriangle, {tri[0], tri[1], tri[2]});
    const std::string file = "steps/tool_" + tc->tool().name + "_" + number + ".vtu";
    io::write_vtu(out.path(file), surface);
    parts_.push_back({lambda, file, part++});
  }
  if (points.points.rows() == 0) return;
  points.point_data.push_back({"pressure", 1, std::move(pressure)});
  points.point_data.push_back({"gap", 1, std::move(gap)});
  points.point_data.push_back({"slip", 3, std::move(slip)});
  points.point_data.push_back({"slip_rate", 3, std::move(slip_rate)});
  points.point_data.push_back({"shear", 3, std::move(shear)});
  points.point_data.push_back({"pair", 1, std::move(pair)});
  const std::string file = std::string("steps/contact_") + number + ".vtu";
  io::write_vtu(out.path(file), points);
  parts_.push_back({lambda, file, part});
}

void FrameSeries::write_collection(const std::string& path) const {
  std::vector<io::PvdDataSet> sets;
  for (const auto& [lambda, name] : frames_) sets.push_back({lambda, name, 0});
  sets.insert(sets.end(), parts_.begin(), parts_.end());
  io::write_pvd(path, sets);
}

}  // namespace sf::forming
