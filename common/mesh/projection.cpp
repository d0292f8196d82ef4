#include "common/mesh/projection.hpp"

// CGAL stays in this translation unit (header-only, slow to compile, private link).
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Search_traits_adapter.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/property_map.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <limits>
#include <map>
#include <mutex>
#include <thread>
#include <utility>

#include "common/basis/hermite.hpp"
#include "common/core/error.hpp"
#include "common/core/parallel.hpp"

namespace sf::mesh {

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using CgalPoint = Kernel::Point_3;
using Sample = std::pair<CgalPoint, std::size_t>;  // sample position, sample id
using SamplePointMap = CGAL::First_of_pair_property_map<Sample>;
using BaseTraits = CGAL::Search_traits_3<Kernel>;
using Traits = CGAL::Search_traits_adapter<Sample, SamplePointMap, BaseTraits>;
using KnnSearch = CGAL::Orthogonal_k_neighbor_search<Traits>;
using Tree = KnnSearch::Tree;

constexpr double kTrustRadius = 0.5;  // largest Newton step in xi
constexpr int kMaxHalvings = 60;      // backtracking cuts per iteration (0.5 * 2^-60 < any tol)
constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Element data in tensor form: x(xi) = sum_{i1,i2} c[i1 + 4 i2] H_i1(xi1) H_i2(xi2).
struct ElementData {
  std::array<Vec3, 16> c{};
  // Bounding box of the Bezier control net, which contains the patch.
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
  std::array<EdgeNeighbour, 4> neighbour;
  bool collapsed = false;
  Index fan = -1;  // collapsed: index of the apex fan (collapsed elements around the apex)
};

// x and its xi-derivatives up to second order.
struct Local {
  Vec3 x = Vec3::Zero(), x1 = Vec3::Zero(), x2 = Vec3::Zero();
  Vec3 x11 = Vec3::Zero(), x12 = Vec3::Zero(), x22 = Vec3::Zero();
};

// x and its first and second xi-derivatives at xi: the 1-D Hermite tables of
// common/basis (inline) contracted with the tensor coefficients.
inline Local evaluate(const ElementData& el, const Vec2& xi) {
  const basis::CubicHermiteTable<2> a = basis::cubic_hermite_table<2>(xi[0]);
  const basis::CubicHermiteTable<2> b = basis::cubic_hermite_table<2>(xi[1]);
  Local out;
  for (int i2 = 0; i2 < 4; ++i2) {
    const Vec3* c = &el.c[4 * i2];
    const Vec3 s0 = a[0][0] * c[0] + a[0][1] * c[1] + a[0][2] * c[2] + a[0][3] * c[3];
    const Vec3 s1 = a[1][0] * c[0] + a[1][1] * c[1] + a[1][2] * c[2] + a[1][3] * c[3];
    const Vec3 s2 = a[2][0] * c[0] + a[2][1] * c[1] + a[2][2] * c[2] + a[2][3] * c[3];
    out.x += b[0][i2] * s0;
    out.x1 += b[0][i2] * s1;
    out.x2 += b[1][i2] * s0;
    out.x11 += b[0][i2] * s2;
    out.x12 += b[1][i2] * s1;
    out.x22 += b[2][i2] * s0;
  }
  return out;
}

// x alone (the kd-tree samples).
inline Vec3 position(const ElementData& el, const Vec2& xi) {
  const std::array<double, 4> a = basis::cubic_hermite_table<0>(xi[0])[0];
  const std::array<double, 4> b = basis::cubic_hermite_table<0>(xi[1])[0];
  Vec3 x = Vec3::Zero();
  for (int i2 = 0; i2 < 4; ++i2) {
    const Vec3* c = &el.c[4 * i2];
    x += b[i2] * (a[0] * c[0] + a[1] * c[1] + a[2] * c[2] + a[3] * c[3]);
  }
  return x;
}

// Iteration state in one element.
struct State {
  Index element = -1;
  Vec2 xi = Vec2::Zero();
  Local ev;
  Vec3 r = Vec3::Zero();  // p - x
  double f = 0.0;         // |r|^2
  Vec2 g = Vec2::Zero();  // gradient of f/2: -x,i . r
};

inline void set_state(State& s, const Vec3& p, const Local& ev) {
  s.ev = ev;
  s.r = p - ev.x;
  s.f = s.r.squaredNorm();
  s.g = Vec2(-ev.x1.dot(s.r), -ev.x2.dot(s.r));
}

// Newton step of the 2-D problem: Hessian if positive definite, else Gauss-Newton
// with a Levenberg shift.
inline Vec2 step2(const Mat2& h, const Mat2& gn, const Vec2& g) {
  const double det = h(0, 0) * h(1, 1) - h(0, 1) * h(1, 0);
  if (h(0, 0) > 0.0 && h(1, 1) > 0.0 && det > 1e-14 * h(0, 0) * h(1, 1)) {
    return Vec2(-(h(1, 1) * g[0] - h(0, 1) * g[1]) / det, -(h(0, 0) * g[1] - h(1, 0) * g[0]) / det);
  }
  const double mu = 1e-8 * (gn(0, 0) + gn(1, 1)) + std::numeric_limits<double>::min();
  const double a = gn(0, 0) + mu, b = gn(0, 1), d = gn(1, 1) + mu;
  const double det2 = a * d - b * b;
  if (!(det2 > 0.0)) return Vec2::Zero();
  return Vec2(-(d * g[0] - b * g[1]) / det2, -(a * g[1] - b * g[0]) / det2);
}

inline double step1(double h, double gn, double g) {
  if (h > 1e-14 * gn && h > 0.0) return -g / h;
  const double a = gn * (1.0 + 1e-8) + std::numeric_limits<double>::min();
  return -g / a;
}

// Local edge at a bound of xi component i:
// xi1 = 0 is edge 3, xi1 = 1 edge 1, xi2 = 0 edge 0, xi2 = 1 edge 2.
inline int bound_edge(int component, bool upper) {
  if (component == 0) return upper ? 1 : 3;
  return upper ? 2 : 0;
}

// Visiting order for a batch: Morton (Z-curve) order of the positions, so that
// consecutive queries touch the same kd-tree nodes and elements (cache locality).
// Empty = input order (small batches). Results do not depend on the order.
std::vector<Index> locality_order(const Eigen::Ref<const Points3>& points) {
  const Index n = points.rows();
  if (n < 4096) return {};
  Vec3 lo = Vec3::Constant(kInf), hi = Vec3::Constant(-kInf);
  for (Index i = 0; i < n; ++i) {
    const Vec3 p = points.row(i).transpose();
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (!(lo.allFinite() && hi.allFinite())) return {};
  const double extent = std::max((hi - lo).maxCoeff(), std::numeric_limits<double>::min());
  const double scale = static_cast<double>((1u << 21) - 1) / extent;
  auto spread = [](std::uint64_t v) {  // 21 bits -> every third bit
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
  };
  std::vector<std::pair<std::uint64_t, Index>> keyed(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) {
    const Vec3 p = points.row(i).transpose();
    std::uint64_t code = 0;
    if (p.allFinite()) {
      const Vec3 q = ((p - lo) * scale).cwiseMax(0.0);
      code = spread(static_cast<std::uint64_t>(q.x())) | spread(static_cast<std::uint64_t>(q.y())) << 1 |
             spread(static_cast<std::uint64_t>(q.z())) << 2;
    }
    keyed[static_cast<std::size_t>(i)] = {code, i};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<Index> order(keyed.size());
  for (std::size_t k = 0; k < keyed.size(); ++k) order[k] = keyed[k].second;
  return order;
}

}  // namespace

// ---------------------------------------------------------------------------

struct SurfaceProjector::Impl {
  ProjectionOptions options;
  std::vector<ElementData> elements;
  std::vector<std::vector<Index>> fans;  // collapsed elements around each apex node
  Tree tree;
  Index n_samples = 0;

  // Result of a walk from one start.
  struct WalkResult {
    State state;
    Projection::Status status = Projection::Status::kFailed;
    int iterations = 0;
  };

  Vec2 sample_xi(std::size_t id) const {
    const auto n = static_cast<std::size_t>(options.samples_per_edge);
    const std::size_t local = id % (n * n);
    return Vec2((static_cast<double>(local % n) + 0.5) / static_cast<double>(n),
                (static_cast<double>(local / n) + 0.5) / static_cast<double>(n));
  }
  Index sample_element(std::size_t id) const {
    const auto n = static_cast<std::size_t>(options.samples_per_edge);
    return static_cast<Index>(id / (n * n));
  }

  // Bound-constrained Newton in s.element from s (evaluated). Returns true when converged.
  bool newton(const Vec3& p, State& s, int& iterations) const;
  // Edge through which the minimum leaves the element (-1: none), by the gradient at s.
  int exit_edge(const State& s, double p_scale) const;
  WalkResult walk(const Vec3& p, Index element, const Vec2& xi_start) const;
  Projection project(const Vec3& p) const;
  static Projection to_projection(const WalkResult& w) {
    Projection out;
    out.element = w.state.element;
    out.xi = w.state.xi;
    out.point = w.state.ev.x;
    out.distance = std::sqrt(w.state.f);
    out.status = w.status;
    out.iterations = w.iterations;
    return out;
  }
};

bool SurfaceProjector::Impl::newton(const Vec3& p, State& s, int& iterations) const {
  const ElementData& el = elements[s.element];
  const double p_scale = p.cwiseAbs().maxCoeff();
  while (iterations < options.max_iterations) {
    ++iterations;
    // Components on a bound with the gradient pushing outward stay fixed (sliding).
    bool fixed[2];
    for (int i = 0; i < 2; ++i) fixed[i] = (s.xi[i] <= 0.0 && s.g[i] > 0.0) || (s.xi[i] >= 1.0 && s.g[i] < 0.0);
    Mat2 gn;
    gn(0, 0) = s.ev.x1.squaredNorm();
    gn(1, 1) = s.ev.x2.squaredNorm();
    gn(0, 1) = gn(1, 0) = s.ev.x1.dot(s.ev.x2);
    Mat2 h = gn;
    h(0, 0) -= s.r.dot(s.ev.x11);
    h(1, 1) -= s.r.dot(s.ev.x22);
    h(0, 1) -= s.r.dot(s.ev.x12);
    h(1, 0) = h(0, 1);
    Vec2 d = Vec2::Zero();
    if (!fixed[0] && !fixed[1]) {
      d = step2(h, gn, s.g);
    } else if (!fixed[0]) {
      d[0] = step1(h(0, 0), gn(0, 0), s.g[0]);
    } else if (!fixed[1]) {
      d[1] = step1(h(1, 1), gn(1, 1), s.g[1]);
    }
    if (!d.allFinite()) d.setZero();
    const double norm = d.norm();
    if (norm > kTrustRadius) d *= kTrustRadius / norm;

    bool accepted = false;
    for (int cut = 0; cut < kMaxHalvings; ++cut) {
      const Vec2 xt = (s.xi + d).cwiseMax(0.0).cwiseMin(1.0);
      const Vec2 dxi = xt - s.xi;
      if (dxi.norm() <= options.xi_tolerance) {
        // Converged. Apply the last (sub-tolerance) step to first order, which is
        // exact to round-off at this size, instead of leaving xi off by up to the
        // tolerance or paying for another evaluation.
        s.xi = xt;
        s.ev.x += s.ev.x1 * dxi[0] + s.ev.x2 * dxi[1];
        s.r = p - s.ev.x;
        s.f = s.r.squaredNorm();
        s.g = Vec2(-s.ev.x1.dot(s.r), -s.ev.x2.dot(s.r));
        return true;
      }
      const Local ev = evaluate(el, xt);
      const Vec3 rt = p - ev.x;
      const double ft = rt.squaredNorm();
      // Allow increases at the round-off level of f (|r| carries ~eps |p| error).
      const double noise = 64.0 * kEps * p_scale * (std::sqrt(s.f) + std::sqrt(ft));
      if (ft <= s.f + noise) {
        s.xi = xt;
        set_state(s, p, ev);
        accepted = true;
        break;
      }
      d *= 0.5;
    }
    if (!accepted) return true;  // no decrease along a descent direction: stationary
  }
  return false;
}

int SurfaceProjector::Impl::exit_edge(const State& s, double p_scale) const {
  const ElementData& el = elements[s.element];
  const Vec3* tangent[2] = {&s.ev.x1, &s.ev.x2};
  int best = -1;
  int best_rank = -1;
  double best_push = 0.0;
  for (int i = 0; i < 2; ++i) {
    const bool lower = s.xi[i] <= 0.0, upper = s.xi[i] >= 1.0;
    if (!lower && !upper) continue;
    const double t2 = tangent[i]->squaredNorm();
    // Outward when the foot point lies beyond the edge by more than xi_tolerance.
    const double tol = options.xi_tolerance * t2 + 64.0 * kEps * p_scale * std::sqrt(t2);
    const double push = lower ? s.g[i] : -s.g[i];
    if (!(push > tol)) continue;
    const int edge = bound_edge(i, upper);
    // Prefer edges with a neighbour, then the apex, then free edges; then the stronger push.
    int rank = 0;
    if (el.collapsed && edge == 0)
      rank = 1;
    else if (el.neighbour[edge].element >= 0)
      rank = 2;
    const double push_mm = push / std::sqrt(t2);
    if (rank > best_rank || (rank == best_rank && push_mm > best_push)) {
      best = edge;
      best_rank = rank;
      best_push = push_mm;
    }
  }
  return best;
}

SurfaceProjector::Impl::WalkResult SurfaceProjector::Impl::walk(const Vec3& p, Index element,
                                                                const Vec2& xi_start) const {
  WalkResult w;
  const double p_scale = p.cwiseAbs().maxCoeff();
  State& s = w.state;
  s.element = element;
  s.xi = xi_start.cwiseMax(0.0).cwiseMin(1.0);
  set_state(s, p, evaluate(elements[element], s.xi));
  int entry_edge = -1;  // edge of the current element the walk came in through
  // Every element visited costs at least one iteration, so the iteration budget
  // also bounds the number of hops.
  for (;;) {
    if (!newton(p, s, w.iterations)) {
      w.status = Projection::Status::kNotConverged;
      return w;
    }
    w.status = Projection::Status::kConverged;
    const int edge = exit_edge(s, p_scale);
    if (edge < 0 || edge == entry_edge) return w;  // interior minimum, or on the edge just crossed
    const ElementData& el = elements[s.element];
    const bool through_apex = el.collapsed && edge == 0;
    if (!through_apex && el.neighbour[edge].element < 0) {
      w.status = Projection::Status::kOnFreeEdge;
      return w;
    }
    if (w.iterations >= options.max_iterations) {  // no budget left for the next element
      w.status = Projection::Status::kNotConverged;
      return w;
    }
    if (through_apex) {
      // Through the apex: continue in the fan element whose radial direction best
      // matches p - x.
      double best_score = 0.0;
      Index best_element = -1;
      double best_xi1 = 0.0;
      const double r_norm = s.r.norm();
      for (Index f : fans[el.fan]) {
        if (f == s.element) continue;
        for (int k = 0; k <= 4; ++k) {
          const double xi1 = 0.25 * k;
          const Vec3 t = evaluate(elements[f], Vec2(xi1, 0.0)).x2;
          const double tn = t.norm();
          if (!(tn > 0.0)) continue;
          const double score = t.dot(s.r) / (tn * r_norm);
          if (score > best_score) {
            best_score = score;
            best_element = f;
            best_xi1 = xi1;
          }
        }
      }
      if (best_element < 0) return w;
      s.element = best_element;
      s.xi = Vec2(best_xi1, 0.0);
      entry_edge = 0;
    } else {
      const EdgeNeighbour& nb = el.neighbour[edge];
      const double t = (edge == 0 || edge == 2) ? s.xi[0] : s.xi[1];
      s.element = nb.element;
      s.xi = edge_point(nb.edge, nb.reversed ? 1.0 - t : t);
      entry_edge = nb.edge;
    }
    set_state(s, p, evaluate(elements[s.element], s.xi));
  }
}

Projection SurfaceProjector::Impl::project(const Vec3& p) const {
  if (elements.empty() || !p.allFinite()) {
    return Projection{};
  }
  const auto k = static_cast<unsigned>(options.candidates);
  KnnSearch search(tree, CgalPoint(p.x(), p.y(), p.z()), k, 0.0, true, KnnSearch::Distance(), true);

  // Distinct candidate elements in order of their nearest sample.
  std::array<std::pair<Index, std::size_t>, 16> small;
  std::vector<std::pair<Index, std::size_t>> large;
  std::pair<Index, std::size_t>* cand = small.data();
  if (k > small.size()) {
    large.resize(k);
    cand = large.data();
  }
  std::size_t n_cand = 0;
  for (auto it = search.begin(); it != search.end(); ++it) {
    const std::size_t id = it->first.second;
    const Index e = sample_element(id);
    bool seen = false;
    for (std::size_t c = 0; c < n_cand && !seen; ++c) seen = cand[c].first == e;
    if (!seen) cand[n_cand++] = {e, id};
  }

  WalkResult best;
  best.state.f = kInf;
  std::array<Index, 16> ended_small;
  std::vector<Index> ended_large;
  Index* ended = ended_small.data();
  if (n_cand > ended_small.size()) {
    ended_large.resize(n_cand);
    ended = ended_large.data();
  }
  std::size_t n_ended = 0;
  for (std::size_t c = 0; c < n_cand; ++c) {
    const Index e = cand[c].first;
    if (std::find(ended, ended + n_ended, e) != ended + n_ended) continue;
    const ElementData& el = elements[e];
    const double bound2 = (el.lo - p).cwiseMax(0.0).cwiseMax(p - el.hi).squaredNorm();  // lower bound of distance^2
    if (bound2 >= best.state.f) continue;
    WalkResult w = walk(p, e, sample_xi(cand[c].second));
    ended[n_ended++] = w.state.element;
    if (w.state.f < best.state.f) best = w;
  }
  return to_projection(best);
}

// ---------------------------------------------------------------------------

void ProjectionOptions::validate() const {
  auto fail = [](const char* option, const char* expected, const std::string& found) {
    throw InputError(std::string("ProjectionOptions.") + option + ": expected " + expected + ", found " + found);
  };
  if (candidates < 1) fail("candidates", "an integer >= 1", std::to_string(candidates));
  if (samples_per_edge < 1 || samples_per_edge > 64)
    fail("samples_per_edge", "an integer in [1, 64]", std::to_string(samples_per_edge));
  if (max_iterations < 1) fail("max_iterations", "an integer >= 1", std::to_string(max_iterations));
  if (!(xi_tolerance > 0.0 && xi_tolerance < 0.1)) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", xi_tolerance);
    fail("xi_tolerance", "a number in (0, 0.1)", buf);
  }
  if (threads < 0) fail("threads", "an integer >= 0 (0 = hardware)", std::to_string(threads));
}

const char* to_string(Projection::Status status) {
  switch (status) {
    case Projection::Status::kConverged:
      return "converged";
    case Projection::Status::kOnFreeEdge:
      return "on_free_edge";
    case Projection::Status::kNotConverged:
      return "not_converged";
    case Projection::Status::kFailed:
      return "failed";
  }
  return "unknown";
}

std::string Projection::brief() const {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%s e=%lld xi=(%.6g,%.6g) d=%.6g it=%d", to_string(status),
                static_cast<long long>(element), xi[0], xi[1], distance, iterations);
  return buf;
}

SurfaceProjector::SurfaceProjector(const SurfaceMesh& mesh, const Eigen::Ref<const MatX>& parameters,
                                   ProjectionOptions options) {
  options.validate();
  if (parameters.rows() != mesh.n_dofs() || parameters.cols() != 3)
    throw InputError("SurfaceProjector: parameters: expected " + std::to_string(mesh.n_dofs()) +
                     " x 3 (n_dofs x 3), found " + std::to_string(parameters.rows()) + " x " +
                     std::to_string(parameters.cols()));
  auto impl = std::make_shared<Impl>();
  impl->options = options;
  const Index n_el = mesh.n_elements();
  impl->elements.resize(n_el);

  // Hermite -> Bernstein: H_i = sum_j M(i, j) B_j.
  Eigen::Matrix4d m;
  m << 1, 1, 0, 0,         //
      0, 1.0 / 3.0, 0, 0,  //
      0, 0, 1, 1,          //
      0, 0, -1.0 / 3.0, 0;
  std::map<Index, Index> fan_of_apex;
  for (Index e = 0; e < n_el; ++e) {
    ElementData& el = impl->elements[e];
    const auto u = mesh.element_parameters(e, parameters);  // 16 x 3
    std::array<Eigen::Matrix4d, 3> coef;
    for (int n = 0; n < 4; ++n) {
      const int a = n & 1, b = n >> 1;
      for (int d = 0; d < 4; ++d) {
        const int i1 = 2 * a + (d & 1), i2 = 2 * b + (d >> 1);
        el.c[i1 + 4 * i2] = u.row(4 * n + d).transpose();
        for (int comp = 0; comp < 3; ++comp) coef[comp](i1, i2) = u(4 * n + d, comp);
      }
    }
    for (int comp = 0; comp < 3; ++comp) {
      const Eigen::Matrix4d bezier = m.transpose() * coef[comp] * m;
      el.lo[comp] = bezier.minCoeff();
      el.hi[comp] = bezier.maxCoeff();
    }
    for (int edge = 0; edge < 4; ++edge) el.neighbour[edge] = mesh.neighbour(e, edge);
    const Element& me = mesh.element(e);
    el.collapsed = me.shape == ElementShape::kCollapsed;
    if (el.collapsed) {
      el.neighbour[0] = EdgeNeighbour{};
      auto [it, inserted] = fan_of_apex.emplace(me.nodes[0], static_cast<Index>(impl->fans.size()));
      if (inserted) impl->fans.emplace_back();
      el.fan = it->second;
      impl->fans[el.fan].push_back(e);
    }
    if (!(el.lo.allFinite() && el.hi.allFinite()))
      throw InputError(
          "SurfaceProjector: parameters: expected finite values, found a non-finite "
          "value in element " +
          std::to_string(e));
  }

  // kd-tree of sample points.
  const int ns = options.samples_per_edge;
  std::vector<Sample> samples;
  samples.reserve(static_cast<std::size_t>(n_el) * ns * ns);
  for (Index e = 0; e < n_el; ++e)
    for (int j = 0; j < ns; ++j)
      for (int i = 0; i < ns; ++i) {
        const std::size_t id = samples.size();
        const Vec3 x = position(impl->elements[e], impl->sample_xi(id));
        samples.emplace_back(CgalPoint(x.x(), x.y(), x.z()), id);
      }
  impl->n_samples = static_cast<Index>(samples.size());
  if (!samples.empty()) {
    impl->tree.insert(samples.begin(), samples.end());
    impl->tree.build();  // now, not lazily inside a (concurrent) query
  }
  impl_ = std::move(impl);
}

Projection SurfaceProjector::project(const Vec3& p) const { return impl_->project(p); }

namespace {

// fn(i) for every i in [0, n), in `order` when it is not empty, on up to
// `threads` std::threads (0: one per core) taking blocks of 256 points.
template <class Fn>
void for_each_point(Index n, const std::vector<Index>& order, int threads, const Fn& fn) {
  constexpr Index kBlock = 256;
  int n_threads = threads;
  if (n_threads == 0) n_threads = default_threads();
  n_threads = static_cast<int>(std::min<Index>(n_threads, (n + kBlock - 1) / kBlock));
  std::atomic<Index> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto worker = [&]() {
    try {
      for (;;) {
        const Index begin = next.fetch_add(kBlock);
        if (begin >= n) break;
        const Index end = std::min(n, begin + kBlock);
        for (Index k = begin; k < end; ++k) fn(order.empty() ? k : order[static_cast<std::size_t>(k)]);
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      next.store(n);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < n_threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace

std::vector<Projection> SurfaceProjector::project_all(const Eigen::Ref<const Points3>& points) const {
  std::vector<Projection> out(static_cast<std::size_t>(points.rows()));
  for_each_point(points.rows(), locality_order(points), impl_->options.threads,
                 [&](Index i) { out[static_cast<std::size_t>(i)] = impl_->project(points.row(i).transpose()); });
  return out;
}

std::vector<Projection> SurfaceProjector::refine_all(const Eigen::Ref<const Points3>& points,
                                                     const std::vector<Index>& elements,
                                                     const std::vector<Vec2>& xi_start) const {
  if (elements.size() != static_cast<std::size_t>(points.rows()) || xi_start.size() != elements.size())
    throw InputError("SurfaceProjector::refine_all: " + std::to_string(points.rows()) + " points but " +
                     std::to_string(elements.size()) + " start elements and " + std::to_string(xi_start.size()) +
                     " start xi");
  std::vector<Projection> out(elements.size());
  for_each_point(points.rows(), locality_order(points), impl_->options.threads, [&](Index i) {
    out[static_cast<std::size_t>(i)] =
        refine(points.row(i).transpose(), elements[static_cast<std::size_t>(i)], xi_start[static_cast<std::size_t>(i)]);
  });
  return out;
}

Projection SurfaceProjector::refine(const Vec3& p, Index element, const Vec2& xi_start) const {
  if (element < 0 || element >= n_elements() || !p.allFinite() || !xi_start.allFinite()) {
    return Projection{};
  }
  return Impl::to_projection(impl_->walk(p, element, xi_start));
}

const ProjectionOptions& SurfaceProjector::options() const { return impl_->options; }
Index SurfaceProjector::n_elements() const { return static_cast<Index>(impl_->elements.size()); }
Index SurfaceProjector::n_samples() const { return impl_->n_samples; }

}  // namespace sf::mesh
