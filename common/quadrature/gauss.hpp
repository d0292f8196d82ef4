#pragma once
// Gauss-Legendre quadrature on [0,1] and tensor-product rules on [0,1]^d.
// An n-point rule integrates polynomials of degree 2n-1 exactly.

#include <Eigen/Core>
#include <vector>

namespace sf::quadrature {

struct Rule1D {
  std::vector<double> points;   // in [0,1], ascending
  std::vector<double> weights;  // sum to 1
};

// n-point Gauss-Legendre rule on [0,1]; 1 <= n <= 32 (computed by Newton on P_n).
Rule1D gauss_legendre(int n);

template <int DIM>
struct TensorRule {
  std::vector<Eigen::Matrix<double, DIM, 1>> points;
  std::vector<double> weights;  // products of 1-D weights; sum to 1
  int size() const { return static_cast<int>(weights.size()); }
};

// Tensor rule with n[i] points in direction i (xi1 fastest).
TensorRule<2> gauss_2d(int n1, int n2);
TensorRule<3> gauss_3d(int n1, int n2, int n3);

}  // namespace sf::quadrature
