#include "gsa/fit.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <random>

#include "common/basis/hermite.hpp"
#include "common/fe/surface_field.hpp"
#include "common/linalg/solver.hpp"
#include "common/quadrature/gauss.hpp"

namespace sf::gsa {

namespace {

// Mean element sizes (arc-length scale factors) in the two xi directions.
std::array<double, 2> element_size(const mesh::Element& el) {
  double h[2] = {0.0, 0.0};
  int n[2] = {0, 0};
  for (int k = 0; k < 4; ++k) {
    const bool apex = el.shape == mesh::ElementShape::kCollapsed && k < 2;
    for (int dir = 0; dir < 2; ++dir) {
      if (apex && dir == 0) continue;
      h[dir] += el.scale[k][dir];
      ++n[dir];
    }
  }
  return {h[0] / n[0], h[1] / n[1]};
}

// Derivative (o1, o2) of the 16 bicubic functions at xi: d^(o1+o2) N / dxi1^o1 dxi2^o2.
Eigen::Matrix<double, 16, 1> bicubic_derivative(const Vec2& xi, int o1, int o2) {
  const auto a = basis::cubic_hermite(xi[0], o1);
  const auto b = basis::cubic_hermite(xi[1], o2);
  Eigen::Matrix<double, 16, 1> out;
  for (int n = 0; n < 4; ++n)
    for (int d = 0; d < 4; ++d)
      out[4 * n + d] = a[2 * (n & 1) + (d & 1)] * b[2 * (n >> 1) + (d >> 1)];
  return out;
}

void add_element_block(linalg::TripletAssembler& asm_, const fe::ElementDofMap& dm,
                       const Eigen::Matrix<double, 16, 16>& ke) {
  const Eigen::MatrixXd kg = dm.t.transpose() * ke * dm.t;
  asm_.add_block(dm.dofs, dm.dofs, kg);
}

}  // namespace

linalg::SparseMatrix PenaltyMatrices::combined(const Penalty& p) const {
  linalg::SparseMatrix out = p.alpha * first + p.beta * second + p.gamma * third + p.delta * fourth;
  out.prune(0.0);
  return out;
}

PenaltyMatrices assemble_penalties(const mesh::SurfaceMesh& mesh) {
  const Index n = mesh.n_dofs();
  linalg::TripletAssembler k1(n, n), k2(n, n), k3(n, n), k4(n, n);
  const auto rule = quadrature::gauss_2d(4, 4);
  // Precompute basis derivatives at the Gauss points.
  struct Orders {
    int o1, o2;
    double w;
  };
  const std::array<Orders, 2> first = {{{1, 0, 1}, {0, 1, 1}}};
  const std::array<Orders, 3> second = {{{2, 0, 1}, {1, 1, 2}, {0, 2, 1}}};
  const std::array<Orders, 4> third = {{{3, 0, 1}, {2, 1, 3}, {1, 2, 3}, {0, 3, 1}}};
  for (Index e = 0; e < mesh.n_elements(); ++e) {
    const mesh::Element& el = mesh.element(e);
    const auto h = element_size(el);
    const double area = h[0] * h[1];
    Eigen::Matrix<double, 16, 16> a1 = Eigen::Matrix<double, 16, 16>::Zero(), a2 = a1, a3 = a1;
    for (int g = 0; g < rule.size(); ++g) {
      const Vec2& xi = rule.points[g];
      const double w = rule.weights[g] * area;
      for (const auto& o : first) {
        const Eigen::Matrix<double, 16, 1> v = bicubic_derivative(xi, o.o1, o.o2) / (std::pow(h[0], o.o1) * std::pow(h[1], o.o2));
        a1.noalias() += (w * o.w) * v * v.transpose();
      }
      for (const auto& o : second) {
        const Eigen::Matrix<double, 16, 1> v = bicubic_derivative(xi, o.o1, o.o2) / (std::pow(h[0], o.o1) * std::pow(h[1], o.o2));
        a2.noalias() += (w * o.w) * v * v.transpose();
      }
      for (const auto& o : third) {
        const Eigen::Matrix<double, 16, 1> v = bicubic_derivative(xi, o.o1, o.o2) / (std::pow(h[0], o.o1) * std::pow(h[1], o.o2));
        a3.noalias() += (w * o.w) * v * v.transpose();
      }
    }
    const fe::ElementDofMap dm = fe::element_dof_map(mesh.element_map(e));
    add_element_block(k1, dm, a1);
    add_element_block(k2, dm, a2);
    add_element_block(k3, dm, a3);
  }
  // Jumps of the normal second derivative across interior edges (third-order term).
  const quadrature::Rule1D line = quadrature::gauss_legendre(4);
  for (Index e = 0; e < mesh.n_elements(); ++e) {
    for (int edge = 0; edge < 4; ++edge) {
      const mesh::EdgeNeighbour& nb = mesh.neighbour(e, edge);
      if (nb.element < 0 || nb.element < e) continue;  // each interior edge once
      const auto he = element_size(mesh.element(e));
      const auto hn = element_size(mesh.element(nb.element));
      const int dir_e = (edge == 1 || edge == 3) ? 0 : 1;      // normal xi direction in e
      const int dir_n = (nb.edge == 1 || nb.edge == 3) ? 0 : 1;  // ... in the neighbour
      const double edge_len = he[1 - dir_e];
      const double h_normal = 0.5 * (he[dir_e] + hn[dir_n]);
      const fe::ElementDofMap dme = fe::element_dof_map(mesh.element_map(e));
      const fe::ElementDofMap dmn = fe::element_dof_map(mesh.element_map(nb.element));
      // Union of dofs.
      std::vector<Index> dofs = dme.dofs;
      for (Index d : dmn.dofs)
        if (std::find(dofs.begin(), dofs.end(), d) == dofs.end()) dofs.push_back(d);
      Eigen::MatrixXd te = Eigen::MatrixXd::Zero(16, dofs.size()), tn = te;
      for (std::size_t j = 0; j < dme.dofs.size(); ++j)
        te.col(std::find(dofs.begin(), dofs.end(), dme.dofs[j]) - dofs.begin()) = dme.t.col(j);
      for (std::size_t j = 0; j < dmn.dofs.size(); ++j)
        tn.col(std::find(dofs.begin(), dofs.end(), dmn.dofs[j]) - dofs.begin()) = dmn.t.col(j);
      Eigen::MatrixXd kj = Eigen::MatrixXd::Zero(dofs.size(), dofs.size());
      Eigen::MatrixXd k4j = Eigen::MatrixXd::Zero(dofs.size(), dofs.size());
      for (std::size_t g = 0; g < line.points.size(); ++g) {
        const double t = line.points[g];
        const double tn_ = nb.reversed ? 1.0 - t : t;
        const Vec2 xe = mesh::edge_point(edge, t), xn = mesh::edge_point(nb.edge, tn_);
        const Eigen::Matrix<double, 16, 1> ve = bicubic_derivative(xe, dir_e == 0 ? 2 : 0, dir_e == 0 ? 0 : 2) / (he[dir_e] * he[dir_e]);
        const Eigen::Matrix<double, 16, 1> vn = bicubic_derivative(xn, dir_n == 0 ? 2 : 0, dir_n == 0 ? 0 : 2) / (hn[dir_n] * hn[dir_n]);
        const Eigen::VectorXd j = te.transpose() * ve - tn.transpose() * vn;
        kj.noalias() += (line.weights[g] * edge_len / h_normal) * j * j.transpose();
        k4j.noalias() += (line.weights[g] * edge_len / (h_normal * h_normal * h_normal)) * j * j.transpose();
        // Jump of the third normal derivative. The sign of an odd derivative flips
        // with the direction of xi: the outward normal of e is +xi at edges 1, 2.
        const double se = (edge == 1 || edge == 2) ? 1.0 : -1.0;
        const double sn = (nb.edge == 1 || nb.edge == 2) ? -1.0 : 1.0;  // same physical direction
        const Eigen::Matrix<double, 16, 1> we =
            bicubic_derivative(xe, dir_e == 0 ? 3 : 0, dir_e == 0 ? 0 : 3) * (se / std::pow(he[dir_e], 3));
        const Eigen::Matrix<double, 16, 1> wn =
            bicubic_derivative(xn, dir_n == 0 ? 3 : 0, dir_n == 0 ? 0 : 3) * (sn / std::pow(hn[dir_n], 3));
        const Eigen::VectorXd j3 = te.transpose() * we - tn.transpose() * wn;
        k4j.noalias() += (line.weights[g] * edge_len / h_normal) * j3 * j3.transpose();
      }
      k3.add_block(dofs, dofs, kj);
      k4.add_block(dofs, dofs, k4j);
    }
  }
  return {k1.compress(), k2.compress(), k3.compress(), k4.compress()};
}

namespace {

std::vector<fe::ElementDofMap> element_dof_maps(const mesh::SurfaceMesh& mesh) {
  std::vector<fe::ElementDofMap> maps(mesh.n_elements());
  for (Index e = 0; e < mesh.n_elements(); ++e) maps[e] = fe::element_dof_map(mesh.element_map(e));
  return maps;
}

// Row d = b(xi_d)^T T_e (the element's 16 local functions mapped to its global dofs),
// written straight into row-major storage: one row per point, in order.
linalg::SparseMatrix collocation(const std::vector<fe::ElementDofMap>& maps, Index n_dofs,
                                 const std::vector<MeshLocation>& locations) {
  const Index n_points = static_cast<Index>(locations.size());
  Eigen::SparseMatrix<double, Eigen::RowMajor, int> rows(n_points, n_dofs);
  Eigen::VectorXi per_row(n_points);
  for (Index d = 0; d < n_points; ++d)
    per_row[d] = locations[d].element < 0 ? 0 : static_cast<int>(maps[locations[d].element].dofs.size());
  rows.reserve(per_row);
  for (Index d = 0; d < n_points; ++d) {
    const MeshLocation& loc = locations[d];
    if (loc.element < 0) continue;
    const fe::ElementDofMap& dm = maps[loc.element];
    const Eigen::Matrix<double, 16, 1> b = bicubic_derivative(loc.xi, 0, 0);
    const Eigen::RowVectorXd row = b.transpose() * dm.t;
    for (std::size_t j = 0; j < dm.dofs.size(); ++j) rows.insert(d, dm.dofs[j]) = row[static_cast<Index>(j)];
  }
  linalg::SparseMatrix out = rows;
  out.makeCompressed();
  return out;
}

}  // namespace

linalg::SparseMatrix collocation_matrix(const mesh::SurfaceMesh& mesh,
                                        const std::vector<MeshLocation>& locations) {
  return collocation(element_dof_maps(mesh), mesh.n_dofs(), locations);
}

struct FitSystem::Impl {
  const mesh::SurfaceMesh* mesh;
  linalg::SparseMatrix phi, wphi, normal;
  VecX w;
  std::vector<bool> used;
  linalg::LinearSolver solver{linalg::SolverKind::kAuto, linalg::MatrixProperty::kSymmetricPositiveDefinite};
  // Hutchinson probes z (n_points x probes) and Phi^T W z, drawn once per system
  // (fixed seed) and reused by every solve with the same number of probes.
  MatX probes, probes_rhs;
};

FitSystem::FitSystem(const mesh::SurfaceMesh& mesh, const std::vector<MeshLocation>& locations,
                     const VecX& weights)
    : impl_(std::make_unique<Impl>()) {
  impl_->mesh = &mesh;
  const std::vector<fe::ElementDofMap> maps = element_dof_maps(mesh);
  impl_->phi = collocation(maps, mesh.n_dofs(), locations);
  impl_->w = weights.size() ? weights : VecX::Ones(impl_->phi.rows());
  impl_->wphi = impl_->w.asDiagonal() * impl_->phi;
  impl_->used = mesh.used_dofs();
  // Sum of w b b^T per element in the element's own basis, then mapped to the
  // global dofs once per element.
  std::vector<Eigen::Matrix<double, 16, 16>> local(mesh.n_elements(), Eigen::Matrix<double, 16, 16>::Zero());
  for (std::size_t d = 0; d < locations.size(); ++d) {
    const MeshLocation& loc = locations[d];
    if (loc.element < 0 || !(impl_->w[static_cast<Index>(d)] > 0.0)) continue;
    const Eigen::Matrix<double, 16, 1> b = bicubic_derivative(loc.xi, 0, 0);
    local[loc.element].selfadjointView<Eigen::Lower>().rankUpdate(b, impl_->w[static_cast<Index>(d)]);
  }
  linalg::TripletAssembler normal(mesh.n_dofs(), mesh.n_dofs());
  for (Index e = 0; e < mesh.n_elements(); ++e) {
    const Eigen::Matrix<double, 16, 16> a = local[e].selfadjointView<Eigen::Lower>();
    add_element_block(normal, maps[e], a);
  }
  impl_->normal = normal.compress();
}

FitSystem::~FitSystem() = default;

FitResult FitSystem::solve(const Eigen::Ref<const MatX>& values, const linalg::SparseMatrix& penalty,
                           const Eigen::Ref<const MatX>& reference, int trace_probes) {
  Impl& s = *impl_;
  FitResult out;
  const Index n = s.mesh->n_dofs();
  const VecX& w = s.w;
  linalg::SparseMatrix k = s.normal + penalty;
  MatX clean = values;  // points with weight 0 may be NaN (not digitised)
  for (Index d = 0; d < clean.rows(); ++d)
    if (!(w[d] > 0.0)) clean.row(d).setZero();
  MatX rhs = s.wphi.transpose() * clean + penalty * reference;
  // Pin dofs nothing determines (unused by every element, or with an empty row).
  std::vector<Index> pinned;
  for (Index i = 0; i < n; ++i)
    if (!s.used[i]) pinned.push_back(i);
  for (Index i : linalg::empty_rows(k))
    if (s.used[i]) pinned.push_back(i);
  if (!pinned.empty()) {
    linalg::TripletAssembler extra(n, n);
    for (Index i : pinned) {
      extra.add(i, i, 1.0);
      rhs.row(i) = reference.row(i);
    }
    k += extra.compress();
  }
  const linalg::SolveReport& rep = s.solver.factorize(k);
  if (!rep.ok()) {
    out.message = "surface fit: the smoothed least-squares system is singular (" + rep.brief() +
                  "); too few points for the mesh (try fewer elements), or all points on a line";
    return out;
  }
  out.parameters = s.solver.solve(rhs);
  if (trace_probes > 0) {
    if (s.probes.cols() != trace_probes) {
      std::mt19937_64 rng(12345);
      s.probes.resize(s.phi.rows(), trace_probes);
      for (Index r = 0; r < s.probes.rows(); ++r) {
        std::uint64_t bits = 0;  // one draw gives the signs of 64 probes
        for (Index c = 0; c < trace_probes; ++c) {
          if (c % 64 == 0) bits = rng();
          s.probes(r, c) = (w[r] > 0.0) ? (((bits >> (c % 64)) & 1U) ? 1.0 : -1.0) : 0.0;
        }
      }
      s.probes_rhs = s.wphi.transpose() * s.probes;
    }
    MatX b = s.probes_rhs;
    for (Index i : pinned) b.row(i).setZero();
    const MatX hz = s.phi * s.solver.solve(b);
    out.edf = (s.probes.array() * hz.array()).sum() / trace_probes;
  }
  out.fitted = s.phi * out.parameters;
  out.residual = (out.fitted - values).rowwise().norm();
  double sum = 0.0;
  Index count = 0;
  for (Index d = 0; d < s.phi.rows(); ++d) {
    if (w[d] <= 0.0) continue;
    sum += out.residual[d] * out.residual[d];
    out.max = std::max(out.max, out.residual[d]);
    ++count;
  }
  out.rms = count ? std::sqrt(sum / count) : 0.0;
  out.ok = out.parameters.allFinite();
  if (!out.ok) out.message = "surface fit: the solution is not finite";
  return out;
}

}  // namespace sf::gsa
