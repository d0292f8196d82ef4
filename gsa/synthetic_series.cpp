#include "gsa/synthetic_series.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace sf::gsa {

SyntheticSeries make_synthetic_series(const SyntheticSeriesOptions& o) {
  SyntheticSeries out;
  io::GridSeries& s = out.series;
  const int n = o.n;
  const Index m = static_cast<Index>(n) * n;
  const double half = 0.5 * (n - 1) * o.spacing;
  const double r2 = std::pow(0.75 * n * o.spacing, 2);
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  s.undeformed.resize(m, 3);
  s.has_ij = true;
  s.sources.push_back("synthetic reference");
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Index p = static_cast<Index>(i) * n + j;
      s.ids.push_back("m" + std::to_string(i) + "_" + std::to_string(j));
      s.i.push_back(i);
      s.j.push_back(j);
      s.where.push_back("synthetic reference:" + std::to_string(p + 1));
      s.undeformed.row(p) << -half + j * o.spacing, -half + i * o.spacing, 0.0;
    }
  const Points3 exact_undeformed = s.undeformed;
  if (o.noise > 0)
    for (Index p = 0; p < m; ++p)
      for (int c = 0; c < 3; ++c) s.undeformed(p, c) += o.noise * gauss(rng);
  if (o.with_sigma) s.sigma_undeformed.assign(static_cast<std::size_t>(m), o.noise);
  for (int k = 0; k < o.stages; ++k) {
    const double t = static_cast<double>(k + 1) / o.stages;
    io::GridStage st;
    st.name = "stage_" + std::to_string(k + 1);
    st.time = k + 1.0;
    st.source = "synthetic " + st.name;
    s.sources.push_back(st.source);
    st.deformed.resize(m, 3);
    st.where.assign(static_cast<std::size_t>(m), "");
    std::vector<ExactStrain> exact(static_cast<std::size_t>(m));
    const double fx = 1.0 + o.stretch * t, fy = 1.0 - o.contraction * t, h = t * o.bulge;
    bool any_flag = false;
    std::vector<std::uint8_t> flags(static_cast<std::size_t>(m), 0);
    for (Index p = 0; p < m; ++p) {
      const double x = exact_undeformed(p, 0), y = exact_undeformed(p, 1);
      st.deformed.row(p) << fx * x, fy * y, h * (1.0 - (x * x + y * y) / r2);
      Eigen::Matrix<double, 3, 2> f;
      f << fx, 0.0, 0.0, fy, -2.0 * h * x / r2, -2.0 * h * y / r2;
      const Eigen::SelfAdjointEigenSolver<Mat2> eig(f.transpose() * f);
      exact[static_cast<std::size_t>(p)].lambda1 = std::sqrt(eig.eigenvalues()[1]);
      exact[static_cast<std::size_t>(p)].lambda2 = std::sqrt(eig.eigenvalues()[0]);
      st.where[static_cast<std::size_t>(p)] = st.source + ":" + std::to_string(p + 1);
      if (o.noise > 0)
        for (int c = 0; c < 3; ++c) st.deformed(p, c) += o.noise * gauss(rng);
      if (o.not_measured > 0 && uniform(rng) < o.not_measured) {
        st.deformed.row(p).setConstant(std::numeric_limits<double>::quiet_NaN());
        flags[static_cast<std::size_t>(p)] = 1;
        any_flag = true;
      }
    }
    if (any_flag) st.not_measured = std::move(flags);
    if (o.with_sigma) st.sigma.assign(static_cast<std::size_t>(m), o.noise);
    s.stages.push_back(std::move(st));
    out.exact.push_back(std::move(exact));
  }
  if (o.not_measured > 0) s.not_measured_rule = "synthetic: drawn at random per stage";
  return out;
}

}  // namespace sf::gsa
