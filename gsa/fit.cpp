#include "gsa/fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <future>
#include <random>
#include <thread>

#include "common/basis/hermite.hpp"
#include "common/core/error.hpp"
#include "common/core/parallel.hpp"
#include "common/fe/surface_field.hpp"
#include "common/linalg/solver.hpp"
#include "common/quadrature/gauss.hpp"

namespace sf::gsa {

namespace {

// Weights inside the edge-jump term P4 (docs/theory/strain.md). The jump of u,nn
// weighs kJumpCurvatureWeight times the jump of u,nnn: the fit is held close to C2
// and the u,nnn jumps (a fourth difference) do the smoothing, which biases smooth
// fields less than when both jumps count alike.
constexpr double kJumpCurvatureWeight = 30.0;
// Edges of an element on the mesh boundary (on the side facing the edge) count
// this much: there the smoother is one-sided and pulls the boundary element
// towards its neighbour's polynomial, a bias that grows with the field's fourth
// derivative at the edge.
constexpr double kBoundaryEdgeWeight = 0.3;

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

void add_element_block(linalg::TripletAssembler& asm_, const fe::ElementDofMap& dm,
                       const Eigen::Matrix<double, 16, 16>& ke) {
  const Eigen::MatrixXd kg = dm.t.transpose() * ke * dm.t;
  asm_.add_block(dm.dofs, dm.dofs, kg);
}

// Values of `a` at the entries of `pattern` (zero where `a` has none). Both are
// compressed column-major with sorted row indices, and a's pattern lies in pattern's.
VecX values_on(const linalg::SparseMatrix& pattern, const linalg::SparseMatrix& a) {
  VecX out = VecX::Zero(pattern.nonZeros());
  for (int c = 0; c < pattern.outerSize(); ++c) {
    int p = pattern.outerIndexPtr()[c];
    const int p_end = pattern.outerIndexPtr()[c + 1];
    for (linalg::SparseMatrix::InnerIterator it(a, c); it; ++it) {
      while (p < p_end && pattern.innerIndexPtr()[p] < it.row()) ++p;
      out[p] = it.value();
    }
  }
  return out;
}

std::vector<fe::ElementDofMap> element_dof_maps(const mesh::SurfaceMesh& mesh) {
  std::vector<fe::ElementDofMap> maps(mesh.n_elements());
  for (Index e = 0; e < mesh.n_elements(); ++e) maps[e] = fe::element_dof_map(mesh.element_map(e));
  return maps;
}

// Position of entry (row, col) in the values of a compressed column-major matrix
// with sorted row indices; -1 when the entry is not stored.
int position(const linalg::SparseMatrix& a, Index row, Index col) {
  const int* begin = a.innerIndexPtr() + a.outerIndexPtr()[col];
  const int* end = a.innerIndexPtr() + a.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, static_cast<int>(row));
  return (it != end && *it == row) ? static_cast<int>(it - a.innerIndexPtr()) : -1;
}

}  // namespace

PenaltyMatrices assemble_penalties(const mesh::SurfaceMesh& mesh) {
  return assemble_penalties(mesh, std::vector<double>(static_cast<std::size_t>(mesh.n_elements()), 1.0));
}

PenaltyMatrices assemble_penalties(const mesh::SurfaceMesh& mesh, const std::vector<double>& element_multiplier) {
  const Index n = mesh.n_dofs();
  linalg::TripletAssembler k1(n, n), k2(n, n), k3(n, n), k4(n, n), kb(n, n);
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
        const Eigen::Matrix<double, 16, 1> v =
            basis::BicubicHermite::derivative(xi, o.o1, o.o2) / (std::pow(h[0], o.o1) * std::pow(h[1], o.o2));
        a1.noalias() += (w * o.w) * v * v.transpose();
      }
      for (const auto& o : second) {
        const Eigen::Matrix<double, 16, 1> v =
            basis::BicubicHermite::derivative(xi, o.o1, o.o2) / (std::pow(h[0], o.o1) * std::pow(h[1], o.o2));
        a2.noalias() += (w * o.w) * v * v.transpose();
      }
      for (const auto& o : third) {
        const Eigen::Matrix<double, 16, 1> v =
            basis::BicubicHermite::derivative(xi, o.o1, o.o2) / (std::pow(h[0], o.o1) * std::pow(h[1], o.o2));
        a3.noalias() += (w * o.w) * v * v.transpose();
      }
    }
    const fe::ElementDofMap dm = fe::element_dof_map(mesh.element_map(e));
    const double me = element_multiplier[static_cast<std::size_t>(e)];
    add_element_block(k1, dm, me * a1);
    add_element_block(k2, dm, me * a2);
    add_element_block(k3, dm, me * a3);
    // Boundary third order: the element's mean |u,sss|^2, on elements with a free edge.
    bool on_boundary = false;
    for (int edge = 0; edge < 4; ++edge)
      on_boundary =
          on_boundary || (mesh.neighbour(e, edge).element < 0 && !mesh::SurfaceMesh::is_degenerate_edge(el, edge));
    if (on_boundary) add_element_block(kb, dm, (me / area) * a3);
  }
  // Jumps of the normal second derivative across interior edges (third-order term).
  const quadrature::Rule1D line = quadrature::gauss_legendre(4);
  for (Index e = 0; e < mesh.n_elements(); ++e) {
    for (int edge = 0; edge < 4; ++edge) {
      const mesh::EdgeNeighbour& nb = mesh.neighbour(e, edge);
      if (nb.element < 0 || nb.element < e) continue;  // each interior edge once
      const auto he = element_size(mesh.element(e));
      const auto hn = element_size(mesh.element(nb.element));
      const int dir_e = (edge == 1 || edge == 3) ? 0 : 1;        // normal xi direction in e
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
      // Is either element on the mesh boundary across from this edge?
      const auto boundary_behind = [&](Index el, int ed) {
        const int opposite = (ed + 2) % 4;
        return mesh.neighbour(el, opposite).element < 0 &&
               !mesh::SurfaceMesh::is_degenerate_edge(mesh.element(el), opposite);
      };
      const double m_edge = std::min(element_multiplier[static_cast<std::size_t>(e)],
                                     element_multiplier[static_cast<std::size_t>(nb.element)]);
      const double w4 =
          m_edge * ((boundary_behind(e, edge) || boundary_behind(nb.element, nb.edge)) ? kBoundaryEdgeWeight : 1.0);
      Eigen::MatrixXd kj = Eigen::MatrixXd::Zero(dofs.size(), dofs.size());
      Eigen::MatrixXd k4j = Eigen::MatrixXd::Zero(dofs.size(), dofs.size());
      for (std::size_t g = 0; g < line.points.size(); ++g) {
        const double t = line.points[g];
        const double tn_ = nb.reversed ? 1.0 - t : t;
        const Vec2 xe = mesh::edge_point(edge, t), xn = mesh::edge_point(nb.edge, tn_);
        const Eigen::Matrix<double, 16, 1> ve =
            basis::BicubicHermite::derivative(xe, dir_e == 0 ? 2 : 0, dir_e == 0 ? 0 : 2) / (he[dir_e] * he[dir_e]);
        const Eigen::Matrix<double, 16, 1> vn =
            basis::BicubicHermite::derivative(xn, dir_n == 0 ? 2 : 0, dir_n == 0 ? 0 : 2) / (hn[dir_n] * hn[dir_n]);
        const Eigen::VectorXd j = te.transpose() * ve - tn.transpose() * vn;
        kj.noalias() += (line.weights[g] * edge_len / h_normal) * j * j.transpose();
        k4j.noalias() += (w4 * kJumpCurvatureWeight * line.weights[g] * edge_len / (h_normal * h_normal * h_normal)) *
                         j * j.transpose();
        // Jump of the third normal derivative. The sign of an odd derivative flips
        // with the direction of xi: the outward normal of e is +xi at edges 1, 2.
        const double se = (edge == 1 || edge == 2) ? 1.0 : -1.0;
        const double sn = (nb.edge == 1 || nb.edge == 2) ? -1.0 : 1.0;  // same physical direction
        const Eigen::Matrix<double, 16, 1> we =
            basis::BicubicHermite::derivative(xe, dir_e == 0 ? 3 : 0, dir_e == 0 ? 0 : 3) *
            (se / std::pow(he[dir_e], 3));
        const Eigen::Matrix<double, 16, 1> wn =
            basis::BicubicHermite::derivative(xn, dir_n == 0 ? 3 : 0, dir_n == 0 ? 0 : 3) *
            (sn / std::pow(hn[dir_n], 3));
        const Eigen::VectorXd j3 = te.transpose() * we - tn.transpose() * wn;
        k4j.noalias() += (w4 * line.weights[g] * edge_len / h_normal) * j3 * j3.transpose();
      }
      k3.add_block(dofs, dofs, m_edge * kj);
      k4.add_block(dofs, dofs, k4j);
    }
  }
  PenaltyMatrices out;
  const std::array<linalg::SparseMatrix, 5> orders = {k1.compress(), k2.compress(), k3.compress(), k4.compress(),
                                                      kb.compress()};
  linalg::SparseMatrix identity(n, n);
  identity.setIdentity();
  out.pattern = orders[0] + orders[1] + orders[2] + orders[3] + orders[4] + identity;
  out.pattern.makeCompressed();
  for (int i = 0; i < 5; ++i) out.order[i] = values_on(out.pattern, orders[i]);
  out.diagonal.resize(static_cast<std::size_t>(n));
  for (int c = 0; c < n; ++c) out.diagonal[static_cast<std::size_t>(c)] = position(out.pattern, c, c);
  out.maps = element_dof_maps(mesh);
  out.element_positions.resize(static_cast<std::size_t>(mesh.n_elements()));
  for (Index e = 0; e < mesh.n_elements(); ++e) {
    const std::vector<Index>& dofs = out.maps[e].dofs;
    std::vector<int>& pos = out.element_positions[static_cast<std::size_t>(e)];
    pos.resize(dofs.size() * dofs.size());
    for (std::size_t j = 0; j < dofs.size(); ++j)
      for (std::size_t i = 0; i < dofs.size(); ++i) pos[i + j * dofs.size()] = position(out.pattern, dofs[i], dofs[j]);
  }
  return out;
}

namespace {

using RowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

// Row d = b(xi_d)^T T_e (the element's 16 local functions mapped to its global dofs),
// written straight into compressed row-major storage, columns ascending.
RowMatrix collocation(const std::vector<fe::ElementDofMap>& maps, Index n_dofs,
                      const std::vector<MeshLocation>& locations) {
  std::vector<std::vector<int>> ascending(maps.size());
  for (std::size_t e = 0; e < maps.size(); ++e) {
    std::vector<int>& o = ascending[e];
    o.resize(maps[e].dofs.size());
    std::iota(o.begin(), o.end(), 0);
    std::sort(o.begin(), o.end(), [&](int i, int j) { return maps[e].dofs[i] < maps[e].dofs[j]; });
  }
  const Index n_points = static_cast<Index>(locations.size());
  RowMatrix rows(n_points, n_dofs);
  int* outer = rows.outerIndexPtr();
  outer[0] = 0;
  for (Index d = 0; d < n_points; ++d) {
    const MeshLocation& loc = locations[d];
    outer[d + 1] = outer[d] + (loc.element >= 0 ? static_cast<int>(maps[loc.element].dofs.size()) : 0);
  }
  rows.resizeNonZeros(outer[n_points]);
  int* inner = rows.innerIndexPtr();
  double* value = rows.valuePtr();
  // The rows on all cores, each at its known place.
  parallel_for(
      n_points,
      [&](Index d) {
        const MeshLocation& loc = locations[d];
        if (loc.element < 0) return;
        const fe::ElementDofMap& dm = maps[loc.element];
        const Eigen::Matrix<double, 16, 1> b = basis::BicubicHermite::derivative(loc.xi, 0, 0);
        const Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, 64> row = b.transpose() * dm.t;
        int p = outer[d];
        for (int j : ascending[loc.element]) {
          inner[p] = static_cast<int>(dm.dofs[j]);
          value[p++] = row[j];
        }
      },
      4096);
  return rows;
}

// out = phi * params (subtract: out -= phi * params); with `rows`, row i of out is row
// rows[i] of phi's. The same operations in the same order as Eigen's sparse x dense
// product (per column and row: a sum from 0 over the row's stored entries in order, then
// added to the zeroed or given entry with alpha = 1 or -1), so every entry is the same
// bits, but each row of Phi is read once for all the columns instead of once per column,
// from parameters laid out a dof per row: 1e5 points x 42 probe columns, at every pilot
// fit, used to stream Phi's 19 MB 42 times. Rows in blocks on all cores.
template <int kCols>
void row_times(const int* inner, const double* value, int p0, int p1, const double* by_dof, Index stride, double* o,
               Index ld, bool subtract) {
  double tmp[kCols];
  for (int c = 0; c < kCols; ++c) tmp[c] = 0.0;
  for (int p = p0; p < p1; ++p) {
    const double v = value[p];
    const double* at = by_dof + static_cast<Index>(inner[p]) * stride;
    for (int c = 0; c < kCols; ++c) tmp[c] += v * at[c];
  }
  for (int c = 0; c < kCols; ++c) {
    double& dst = o[c * ld];
    dst = subtract ? dst + -1.0 * tmp[c] : 0.0 + 1.0 * tmp[c];
  }
}

void rows_times(const RowMatrix& phi, const MatX& params, MatX& out, bool subtract,
                const std::vector<Index>* rows = nullptr) {
  constexpr Index kRows = 2048;
  constexpr Index kGroup = 8;  // columns summed together (their partial sums in registers)
  const Index n = rows ? static_cast<Index>(rows->size()) : phi.rows();
  const Index cols = params.cols();
  if (!subtract) out.resize(n, cols);
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> by_dof = params;
  const double* pd = by_dof.data();
  const int* outer = phi.outerIndexPtr();
  const int* inner = phi.innerIndexPtr();
  const double* value = phi.valuePtr();
  double* o = out.data();
  const Index ld = out.rows();
  using Kernel = void (*)(const int*, const double*, int, int, const double*, Index, double*, Index, bool);
  static constexpr Kernel kernels[kGroup + 1] = {nullptr,      row_times<1>, row_times<2>, row_times<3>, row_times<4>,
                                                 row_times<5>, row_times<6>, row_times<7>, row_times<8>};
  parallel_for((n + kRows - 1) / kRows,
               [&](Index b) {
                 const Index first = b * kRows, last = std::min(n, first + kRows);
                 for (Index i = first; i < last; ++i) {
                   const Index r = rows ? (*rows)[static_cast<std::size_t>(i)] : i;
                   for (Index c0 = 0; c0 < cols; c0 += kGroup) {
                     const Index nc = std::min(kGroup, cols - c0);
                     kernels[nc](inner, value, outer[r], outer[r + 1], pd + c0, cols, o + c0 * ld + i, ld, subtract);
                   }
                 }
               },
               1);
}

// out = Phi^T (...) (n_dofs x values.cols()) in groups of up to 8 columns, the groups on all
// cores: `point(d, z, o, nc)` adds point d's terms to the group's output columns o[c] from
// its value columns z[c]. Each entry sums over the points in their order whatever the
// threads; Phi is read once per group instead of once per column.
constexpr Index kColumnGroup = 8;
template <class Point>
MatX by_column_groups(const RowMatrix& phi, const Eigen::Ref<const MatX>& values, const Point& point) {
  const Index cols = values.cols(), groups = (cols + kColumnGroup - 1) / kColumnGroup;
  MatX out = MatX::Zero(phi.cols(), cols);
  parallel_for(
      groups,
      [&](Index g) {
        const Index c0 = g * kColumnGroup, nc = std::min(kColumnGroup, cols - c0);
        const double* z[kColumnGroup];
        double* o[kColumnGroup];
        for (Index c = 0; c < nc; ++c) z[c] = values.col(c0 + c).data(), o[c] = out.col(c0 + c).data();
        for (Index d = 0; d < phi.rows(); ++d) point(d, z, o, nc);
      },
      1);
  return out;
}

// phi^T values, or with `w` phi^T (diag(w) values): the operations of Eigen's product of
// the transposed sparse matrix with a dense one in its order (each entry summed over the
// points in turn from 0, of value x (w_d z_d)), so the same bits (the probes of the trace
// estimates: 6 to 12 columns, twice per system).
MatX transpose_times(const RowMatrix& phi, const MatX& values, const VecX* w) {
  return by_column_groups(phi, values, [&](Index d, const double* const* z, double* const* o, Index nc) {
    double zd[kColumnGroup];
    for (Index c = 0; c < nc; ++c) zd[c] = 1.0 * (w ? (*w)[d] * z[c][d] : z[c][d]);
    for (RowMatrix::InnerIterator it(phi, d); it; ++it) {
      const double a = it.value();
      const Index j = it.col();
      for (Index c = 0; c < nc; ++c) o[c][j] += a * zd[c];
    }
  });
}

// add + pen x as Eigen forms it (a copy of add, and the product's terms added to it in
// the product's order: over pen's columns in turn), so the same bits, with pen read once
// for up to 8 columns of x instead of once per column. A zero x (the probes' and
// pilots' zero reference) adds zeros only, which change no entry but a -0 (none in
// practice; then the terms are added as before): add, without the product.
MatX plus_product(const MatX& add, const linalg::SparseMatrix& pen, const Eigen::Ref<const MatX>& x) {
  MatX out = add;
  if ((x.array() == 0.0).all() &&
      !(add.array() == 0.0 && add.array().unaryExpr([](double v) { return std::signbit(v); })).any())
    return out;
  constexpr Index kGroup = 8;
  const Index ld = out.rows();
  for (Index c0 = 0; c0 < x.cols(); c0 += kGroup) {
    const Index nc = std::min(kGroup, x.cols() - c0);
    double* o = out.data() + c0 * ld;
    double xj[kGroup];
    for (Index j = 0; j < pen.outerSize(); ++j) {
      for (Index c = 0; c < nc; ++c) xj[c] = 1.0 * x(j, c0 + c);
      for (linalg::SparseMatrix::InnerIterator it(pen, j); it; ++it) {
        const double v = it.value();
        double* oi = o + it.row();
        for (Index c = 0; c < nc; ++c) oi[c * ld] += v * xj[c];
      }
    }
  }
  return out;
}

// pen = sum over t of weight[t] * values[t] (in that order, from the first term: no zero
// added first) and k = normal + pen, entry by entry in one pass; the term count is fixed
// at compile time so that the loop is vectorised.
template <int kTerms>
void weighted_sum_of(const std::array<double, 5>& weight, const std::array<const double*, 5>& values,
                     const double* normal, double* pen, double* k, Index n) {
  for (Index i = 0; i < n; ++i) {
    double p = 0.0;
    if constexpr (kTerms > 0) {
      p = weight[0] * values[0][i];
      for (int t = 1; t < kTerms; ++t) p += weight[t] * values[t][i];
    }
    pen[i] = p;
    k[i] = normal[i] + p;
  }
}
void weighted_sum(int terms, const std::array<double, 5>& weight, const std::array<const double*, 5>& values,
                  const double* normal, double* pen, double* k, Index n) {
  switch (terms) {
    case 0:
      return weighted_sum_of<0>(weight, values, normal, pen, k, n);
    case 1:
      return weighted_sum_of<1>(weight, values, normal, pen, k, n);
    case 2:
      return weighted_sum_of<2>(weight, values, normal, pen, k, n);
    case 3:
      return weighted_sum_of<3>(weight, values, normal, pen, k, n);
    case 4:
      return weighted_sum_of<4>(weight, values, normal, pen, k, n);
    default:
      return weighted_sum_of<5>(weight, values, normal, pen, k, n);
  }
}

}  // namespace

// What one solve changes: K and the penalty on the common pattern, the
// factorisation. Two of them let two penalties be solved at once. Both use CHOLMOD's
// supernodal Cholesky: on these matrices it takes under half the processor time of the
// simplicial one (n = 2116, 311k entries in the factor at 1e5 marks: 0.010 against
// 0.023 s, 5.6 against 2.5 GFLOP/s). Its factorisations and solves call the serial
// OpenBLAS, which is not safe on two threads at once (wrong fits now and then);
// linalg::LinearSolver runs them one at a time (its BLAS section), so a pair's two
// factorisations take turns while the rest of the two fits still runs side by side.
struct FitWorkspace {
  linalg::SparseMatrix k, pen;
  VecX factored;  // values of the K last factorised
  linalg::LinearSolver solver{linalg::SolverKind::kCholmod, linalg::MatrixProperty::kSymmetricPositiveDefinite};
};

struct FitSystem::Impl {
  const mesh::SurfaceMesh* mesh = nullptr;
  const PenaltyMatrices* penalties = nullptr;
  RowMatrix phi;  // n_points x n_dofs
  VecX w;
  std::vector<bool> used;
  VecX normal_values;  // Phi^T W Phi on the penalties' pattern
  std::array<std::unique_ptr<FitWorkspace>, 2> work;
  MatX values, data_rhs;  // z and Phi^T W z
  // Hutchinson probes z (n_points x probes), drawn once per system (fixed seed)
  // and reused by every solve with the same number of probes, and Phi^T z, Phi^T W z.
  MatX probes, probes_plain, probes_weighted;

  FitWorkspace& workspace(int i) {
    SF_ASSERT(i == 0 || i == 1, "a fit system has two workspaces");
    if (!work[i]) {
      work[i] = std::make_unique<FitWorkspace>();
      work[i]->k = work[i]->pen = penalties->pattern;
    }
    return *work[i];
  }
  void draw_probes(int count);
  // Phi^T W z over the points with weight > 0 (the others may be NaN).
  MatX weighted_rhs(const Eigen::Ref<const MatX>& values) const;
  // K (data weights + penalty) factorised in `ws` (reused when unchanged) and the dof
  // parameters of the fit of the data whose Phi^T W z is `rhs_data`; `pinned` gets the
  // dofs pinned to the reference. Empty with `message` set when K is singular.
  MatX parameters(FitWorkspace& ws, const Penalty& penalty, const Eigen::Ref<const MatX>& reference,
                  const MatX& rhs_data, int passes, std::vector<Index>& pinned, std::string& message) const;
  FitResult solve(FitWorkspace& ws, const Penalty& penalty, const Eigen::Ref<const MatX>& reference, int trace_probes,
                  int passes) const;
};

FitSystem::FitSystem(const mesh::SurfaceMesh& mesh, const PenaltyMatrices& penalties,
                     const std::vector<MeshLocation>& locations, const VecX& weights)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.mesh = &mesh;
  s.penalties = &penalties;
  s.w = weights.size() ? weights : VecX::Ones(static_cast<Index>(locations.size()));
  s.used = mesh.used_dofs();
  // Sum of w b b^T per element in the element's own basis, then mapped to the global
  // dofs and added into the pattern's values once per element. The elements are split
  // into one range per thread; each range's sums take the points in their order, as
  // one thread would, so the sums are the same bits whatever the threads.
  s.phi = collocation(penalties.maps, mesh.n_dofs(), locations);
  const Index n_elements = mesh.n_elements();
  std::vector<Eigen::Matrix<double, 16, 16>> local(static_cast<std::size_t>(n_elements),
                                                   Eigen::Matrix<double, 16, 16>::Zero());
  const Index parts = std::min<Index>(default_threads(), std::max<Index>(1, n_elements));
  parallel_for(
      parts,
      [&](Index part) {
        const Index e0 = n_elements * part / parts, e1 = n_elements * (part + 1) / parts;
        for (std::size_t d = 0; d < locations.size(); ++d) {
          const MeshLocation& loc = locations[d];
          if (loc.element < e0 || loc.element >= e1 || !(s.w[static_cast<Index>(d)] > 0.0)) continue;
          const Eigen::Matrix<double, 16, 1> b = basis::BicubicHermite::derivative(loc.xi, 0, 0);
          local[loc.element].noalias() += (s.w[static_cast<Index>(d)] * b) * b.transpose();
        }
      },
      1, static_cast<int>(parts));
  s.normal_values = VecX::Zero(penalties.pattern.nonZeros());
  for (Index e = 0; e < mesh.n_elements(); ++e) {
    const fe::ElementDofMap& dm = penalties.maps[e];
    const Eigen::MatrixXd kg = dm.t.transpose() * local[e] * dm.t;
    const std::vector<int>& pos = penalties.element_positions[static_cast<std::size_t>(e)];
    for (Index k = 0; k < kg.size(); ++k) s.normal_values[pos[static_cast<std::size_t>(k)]] += kg.data()[k];
  }
}

FitSystem::~FitSystem() = default;

MatX FitSystem::Impl::weighted_rhs(const Eigen::Ref<const MatX>& values) const {
  // Groups of up to 8 columns on all cores, a group's columns summed together: each entry
  // still sums over the points in their order, the same products in the same order as
  // one column at a time, whatever the threads.
  return by_column_groups(phi, values, [&](Index d, const double* const* zc, double* const* o, Index nc) {
    if (!(w[d] > 0.0)) return;
    for (RowMatrix::InnerIterator it(phi, d); it; ++it) {
      const double a = w[d] * it.value();
      const Index j = it.col();
      for (Index c = 0; c < nc; ++c) o[c][j] += a * zc[c][d];
    }
  });
}

void FitSystem::set_values(const Eigen::Ref<const MatX>& values) {
  Impl& s = *impl_;
  s.values = values;
  s.data_rhs = s.weighted_rhs(values);
}

std::optional<MatX> FitSystem::smoothing_residual(const Eigen::Ref<const MatX>& values, const Penalty& penalty,
                                                  int passes) {
  return smoothing_residual(values, impl_->weighted_rhs(values), penalty, passes, 0);
}

MatX FitSystem::weighted_values(const Eigen::Ref<const MatX>& values) const { return impl_->weighted_rhs(values); }

std::optional<MatX> FitSystem::smoothing_residual(const Eigen::Ref<const MatX>& values, const MatX& weighted,
                                                  const Penalty& penalty, int passes, int slot,
                                                  const std::vector<Index>* rows) {
  const Impl& s = *impl_;
  std::vector<Index> pinned;
  std::string message;
  const MatX zero = MatX::Zero(s.mesh->n_dofs(), values.cols());
  const MatX params = s.parameters(impl_->workspace(slot), penalty, zero, weighted, passes, pinned, message);
  if (params.size() == 0) return std::nullopt;
  if (rows) {
    // The rows asked for: each row's product is the same sum as in the whole.
    MatX out(static_cast<Index>(rows->size()), values.cols());
    // The values gathered a column at a time (the values are column-major: a row is one entry per
    // column, each in another cache line), the columns on all cores.
    const Index n_rows = static_cast<Index>(rows->size());
    parallel_for(
        values.cols(),
        [&](Index c) {
          const double* from = values.col(c).data();
          double* to = out.col(c).data();
          for (Index i = 0; i < n_rows; ++i) to[i] = from[(*rows)[static_cast<std::size_t>(i)]];
        },
        4);
    rows_times(s.phi, params, out, true, rows);
    return out;
  }
  MatX out = values;
  rows_times(s.phi, params, out, true);
  return out;
}

void FitSystem::set_probes(const MatX& p) {
  Impl& s = *impl_;
  s.probes = p;
  for (Index r = 0; r < p.rows(); ++r)
    if (!(s.w[r] > 0.0)) s.probes.row(r).setZero();
  s.probes_plain = transpose_times(s.phi, s.probes, nullptr);
  s.probes_weighted = transpose_times(s.phi, s.probes, &s.w);
}

void FitSystem::Impl::draw_probes(int count) {
  if (probes.cols() == count) return;
  std::mt19937_64 rng(12345);
  probes.resize(phi.rows(), count);
  for (Index r = 0; r < probes.rows(); ++r) {
    std::uint64_t bits = 0;  // one draw gives the signs of 64 probes
    for (Index c = 0; c < count; ++c) {
      if (c % 64 == 0) bits = rng();
      probes(r, c) = (w[r] > 0.0) ? (((bits >> (c % 64)) & 1U) ? 1.0 : -1.0) : 0.0;
    }
  }
  probes_plain = transpose_times(phi, probes, nullptr);
  probes_weighted = transpose_times(phi, probes, &w);
}

MatX FitSystem::Impl::parameters(FitWorkspace& ws, const Penalty& penalty, const Eigen::Ref<const MatX>& reference,
                                 const MatX& rhs_data, int passes, std::vector<Index>& pinned,
                                 std::string& message) const {
  const Index n = mesh->n_dofs();
  const std::array<VecX, 5>& order = penalties->order;
  // The penalty's values, the orders weighted and summed in order, and K = normal +
  // penalty, in one pass over the pattern. Orders of weight 0 are left out (jumps: alpha
  // and beta): a zero term changes no sum but the sign of a zero, so the values are the
  // same bits as the whole sum's (a third of the processor time of a smoothing-choice
  // fit outside CHOLMOD was this sum, read from five arrays of the pattern's size).
  const double weight[5] = {penalty.alpha, penalty.beta, penalty.gamma, penalty.delta,
                            penalty.boundary > 0.0 ? penalty.boundary : 0.0};
  std::array<const double*, 5> term_values{};
  std::array<double, 5> term_weight{};
  int terms = 0;
  for (int k = 0; k < 5; ++k)
    if (weight[k] != 0.0) term_values[terms] = order[k].data(), term_weight[terms++] = weight[k];
  weighted_sum(terms, term_weight, term_values, normal_values.data(), ws.pen.valuePtr(), ws.k.valuePtr(),
               ws.k.nonZeros());
  Eigen::Map<VecX> k_values(ws.k.valuePtr(), ws.k.nonZeros());
  MatX rhs = plus_product(rhs_data, ws.pen, reference);
  // Pin dofs nothing determines (unused by every element, or with an empty row).
  pinned.clear();
  for (Index i = 0; i < n; ++i)
    if (!used[i]) pinned.push_back(i);
  for (Index i : linalg::empty_rows(ws.k))
    if (used[i]) pinned.push_back(i);
  for (Index i : pinned) {
    k_values[penalties->diagonal[static_cast<std::size_t>(i)]] += 1.0;
    rhs.row(i) = reference.row(i);
  }
  if (ws.factored.size() != k_values.size() || ws.factored != k_values) {
    const linalg::SolveReport& rep = ws.solver.factorize(ws.k);
    ws.factored = k_values;
    if (!rep.ok()) {
      ws.factored.resize(0);
      message = "surface fit: the smoothed least-squares system is singular (" + rep.brief() +
                "); too few points for the mesh (try fewer elements), or all points on a line";
      return MatX();
    }
  }
  MatX parameters = ws.solver.solve(rhs);
  // Further passes penalise the deviation from the previous pass (same matrix).
  for (int pass = 1; pass < passes; ++pass) {
    MatX r = plus_product(rhs_data, ws.pen, parameters);
    for (Index i : pinned) r.row(i) = reference.row(i);
    parameters = ws.solver.solve(r);
  }
  return parameters;
}

FitResult FitSystem::Impl::solve(FitWorkspace& ws, const Penalty& penalty, const Eigen::Ref<const MatX>& reference,
                                 int trace_probes, int passes) const {
  FitResult out;
  std::vector<Index> pinned;
  out.parameters = parameters(ws, penalty, reference, data_rhs, passes, pinned, out.message);
  if (out.parameters.size() == 0) return out;
  if (trace_probes > 0) {
    // z^T Phi H Phi^T W z = (Phi^T z)^T H (Phi^T W z) with H the (iterated)
    // smoother in dof space: all in dof space.
    MatX b = probes_weighted;
    for (Index i : pinned) b.row(i).setZero();
    MatX hb = ws.solver.solve(b);
    for (int pass = 1; pass < passes; ++pass) {
      MatX r = plus_product(b, ws.pen, hb);
      for (Index i : pinned) r.row(i).setZero();
      hb = ws.solver.solve(r);
    }
    out.edf = (probes_plain.array() * hb.array()).sum() / trace_probes;
  }
  rows_times(phi, out.parameters, out.fitted, false);
  out.residual = (out.fitted - values).rowwise().norm();
  double sum = 0.0;
  Index count = 0;
  for (Index d = 0; d < phi.rows(); ++d) {
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

FitResult FitSystem::solve(const Penalty& penalty, const Eigen::Ref<const MatX>& reference, int trace_probes,
                           int passes, int slot) {
  if (trace_probes > 0) impl_->draw_probes(trace_probes);
  return impl_->solve(impl_->workspace(slot), penalty, reference, trace_probes, passes);
}

std::array<FitResult, 2> FitSystem::solve_pair(const std::array<Penalty, 2>& penalties,
                                               const Eigen::Ref<const MatX>& reference, int trace_probes, int passes) {
  Impl& s = *impl_;
  if (trace_probes > 0) s.draw_probes(trace_probes);
  FitWorkspace& first = s.workspace(0);
  FitWorkspace& second = s.workspace(1);
  std::array<FitResult, 2> out;
  if (default_threads() < 2) {
    out[0] = s.solve(first, penalties[0], reference, trace_probes, passes);
    out[1] = s.solve(second, penalties[1], reference, trace_probes, passes);
    return out;
  }
  std::thread other([&] { out[1] = s.solve(second, penalties[1], reference, trace_probes, passes); });
  out[0] = s.solve(first, penalties[0], reference, trace_probes, passes);
  other.join();
  return out;
}

}  // namespace sf::gsa
