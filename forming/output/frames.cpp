#include "forming/output/frames.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "forming/material/material.hpp"
#include "forming/output/sampling.hpp"

namespace sf::forming {

io::VolumeMesh tessellate(const Model& model, const VecX& x, int samples_inplane, int samples_thickness) {
  const int ns = samples_inplane, nt = samples_thickness;
  io::VolumeMesh mesh;
  std::vector<Vec3> points;
  std::vector<double> disp, stress, fibre, stretch, body_id, pressure, tension;
  const bool constrained = model.any_constrained();
  for (int b = 0; b < model.n_bodies(); ++b) {
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
            const BrickPoint s = sample_brick(Xe, xe, Vec3(double(i) / ns, double(j) / ns, double(k) / nt));
            points.push_back(s.x);
            for (int c = 0; c < 3; ++c) disp.push_back(s.x[c] - s.X[c]);
          }
      auto pid = [&](int i, int j, int k) { return first + (static_cast<Index>(k) * (ns + 1) + j) * (ns + 1) + i; };
      for (int k = 0; k < nt; ++k)
        for (int j = 0; j < ns; ++j)
          for (int i = 0; i < ns; ++i) {
            mesh.add_cell(io::CellType::kHexahedron,
                          {pid(i, j, k), pid(i + 1, j, k), pid(i + 1, j + 1, k), pid(i, j + 1, k),
                           pid(i, j, k + 1), pid(i + 1, j, k + 1), pid(i + 1, j + 1, k + 1), pid(i, j + 1, k + 1)});
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
          }
    }
  }
  mesh.points.resize(static_cast<Index>(points.size()), 3);
  for (std::size_t p = 0; p < points.size(); ++p) mesh.points.row(static_cast<Index>(p)) = points[p].transpose();
  mesh.point_data.push_back({"displacement", 3, std::move(disp)});
  mesh.cell_data.push_back({"cauchy_stress", 6, std::move(stress)});
  mesh.cell_data.push_back({"fibre_direction", 3, std::move(fibre)});
  mesh.cell_data.push_back({"fibre_stretch", 1, std::move(stretch)});
  mesh.cell_data.push_back({"ply", 1, std::move(body_id)});
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

void FrameSeries::write(const io::AtomicOutputDir& out, int k, double lambda, const VecX& x) {
  const std::string name = step_file_name(k);
  io::write_vtu(out.path(name), tessellate(model_, x, samples_inplane_, samples_thickness_));
  frames_.erase(std::remove_if(frames_.begin(), frames_.end(), [&](const auto& f) { return f.second == name; }),
                frames_.end());
  frames_.emplace_back(lambda, name);
}

void FrameSeries::write_collection(const std::string& path) const { io::write_pvd(path, frames_); }

}  // namespace sf::forming
