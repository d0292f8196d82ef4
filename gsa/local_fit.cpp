#include "gsa/local_fit.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "common/mesh/neighbours.hpp"

namespace sf::gsa {

std::vector<std::optional<LocalStretch>> local_fit_stretches(const GridData& grid, int neighbours) {
  const Index n = grid.n_points();
  // Points with both positions take part.
  Points3 X(n, 3);
  for (Index p = 0; p < n; ++p) {
    X.row(p) = grid.undeformed.row(p);
    if (!grid.has_deformed(p)) X.row(p).setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  const std::vector<std::vector<Index>> nb = mesh::nearest_neighbours(X, neighbours);
  std::vector<std::optional<LocalStretch>> out(static_cast<std::size_t>(n));
  for (Index p = 0; p < n; ++p) {
    const std::vector<Index>& ids = nb[static_cast<std::size_t>(p)];
    if (ids.size() < 3) continue;
    const Index m = static_cast<Index>(ids.size()) + 1;
    Points3 A(m, 3), B(m, 3);
    A.row(0) = X.row(p);
    B.row(0) = grid.deformed.row(p);
    for (Index k = 1; k < m; ++k) {
      A.row(k) = X.row(ids[static_cast<std::size_t>(k - 1)]);
      B.row(k) = grid.deformed.row(ids[static_cast<std::size_t>(k - 1)]);
    }
    const Eigen::RowVector3d ca = A.colwise().mean(), cb = B.colwise().mean();
    const MatX a = A.rowwise() - ca, b = B.rowwise() - cb;
    const Eigen::SelfAdjointEigenSolver<Mat3> pca(a.transpose() * a);
    const Mat32 axes = pca.eigenvectors().rightCols<2>();  // the two largest: tangent plane
    const MatX st = a * axes;                              // m x 2 in-plane coordinates
    const Mat2 ata = st.transpose() * st;
    if (!(std::abs(ata.determinant()) > 1e-12 * ata.squaredNorm())) continue;
    const Mat32 F = (b.transpose() * st) * ata.inverse();  // 3 x 2
    const Eigen::SelfAdjointEigenSolver<Mat2> es(F.transpose() * F);
    const Vec2 l2 = es.eigenvalues();
    out[static_cast<std::size_t>(p)] = LocalStretch{std::sqrt(std::max(0.0, l2[1])), std::sqrt(std::max(0.0, l2[0]))};
  }
  return out;
}

}  // namespace sf::gsa
