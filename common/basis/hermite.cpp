#include "common/basis/hermite.hpp"

namespace sf::basis {

std::array<double, 4> cubic_hermite(double t, int derivative_order) {
  switch (derivative_order) {
    case 0:
      return cubic_hermite_table<0>(t)[0];
    case 1:
      return cubic_hermite_table<1>(t)[1];
    case 2:
      return cubic_hermite_table<2>(t)[2];
    case 3:
      return cubic_hermite_table<3>(t)[3];
    default:
      return {0.0, 0.0, 0.0, 0.0};
  }
}

std::array<double, 2> linear_lagrange(double t, int derivative_order) {
  switch (derivative_order) {
    case 0:
      return {1.0 - t, t};
    case 1:
      return {-1.0, 1.0};
    default:
      return {0.0, 0.0};
  }
}

namespace {
// 1-D tables up to second derivative: h[order][function].
struct Hermite1D {
  std::array<std::array<double, 4>, 3> h;
  Hermite1D(double t, int max_order) {
    for (int o = 0; o <= 2; ++o) h[o] = o <= max_order ? cubic_hermite(t, o) : std::array<double, 4>{};
  }
};
struct Linear1D {
  std::array<std::array<double, 2>, 2> l;
  explicit Linear1D(double t) : l{linear_lagrange(t, 0), linear_lagrange(t, 1)} {}
};
int max_order(unsigned updates) { return (updates & kSecond) ? 2 : ((updates & kFirst) ? 1 : 0); }
}  // namespace

BicubicValues BicubicHermite::evaluate(const Eigen::Vector2d& xi, unsigned updates) {
  BicubicValues out;
  out.updated = updates;
  const int mo = max_order(updates);
  const Hermite1D u(xi[0], mo), v(xi[1], mo);
  for (int n = 0; n < 4; ++n) {
    const int a = n & 1, b = n >> 1;
    for (int d = 0; d < 4; ++d) {
      const int k = 4 * n + d;
      const int i1 = 2 * a + (d & 1), i2 = 2 * b + (d >> 1);
      if (updates & kValues) out.value[k] = u.h[0][i1] * v.h[0][i2];
      if (updates & kFirst) {
        out.first(k, 0) = u.h[1][i1] * v.h[0][i2];
        out.first(k, 1) = u.h[0][i1] * v.h[1][i2];
      }
      if (updates & kSecond) {
        out.second(k, 0) = u.h[2][i1] * v.h[0][i2];
        out.second(k, 1) = u.h[1][i1] * v.h[1][i2];
        out.second(k, 2) = u.h[0][i1] * v.h[2][i2];
      }
    }
  }
  return out;
}

Eigen::Matrix<double, 16, 1> BicubicHermite::derivative(const Eigen::Vector2d& xi, int o1, int o2) {
  const std::array<double, 4> a = cubic_hermite(xi[0], o1), b = cubic_hermite(xi[1], o2);
  Eigen::Matrix<double, 16, 1> out;
  for (int n = 0; n < 4; ++n)
    for (int d = 0; d < 4; ++d) out[4 * n + d] = a[2 * (n & 1) + (d & 1)] * b[2 * (n >> 1) + (d >> 1)];
  return out;
}

BrickValues BicubicHermiteLinear::evaluate(const Eigen::Vector3d& xi, unsigned updates) {
  BrickValues out;
  out.updated = updates;
  const int mo = max_order(updates);
  const Hermite1D u(xi[0], mo), v(xi[1], mo);
  const Linear1D w(xi[2]);
  for (int n = 0; n < 8; ++n) {
    const int a = n & 1, b = (n >> 1) & 1, c = n >> 2;
    for (int d = 0; d < 4; ++d) {
      const int k = 4 * n + d;
      const int i1 = 2 * a + (d & 1), i2 = 2 * b + (d >> 1);
      const double w0 = w.l[0][c], w1 = w.l[1][c];
      if (updates & kValues) out.value[k] = u.h[0][i1] * v.h[0][i2] * w0;
      if (updates & kFirst) {
        out.first(k, 0) = u.h[1][i1] * v.h[0][i2] * w0;
        out.first(k, 1) = u.h[0][i1] * v.h[1][i2] * w0;
        out.first(k, 2) = u.h[0][i1] * v.h[0][i2] * w1;
      }
      if (updates & kSecond) {
        out.second(k, 0) = u.h[2][i1] * v.h[0][i2] * w0;
        out.second(k, 1) = u.h[1][i1] * v.h[1][i2] * w0;
        out.second(k, 2) = u.h[1][i1] * v.h[0][i2] * w1;
        out.second(k, 3) = u.h[0][i1] * v.h[2][i2] * w0;
        out.second(k, 4) = u.h[0][i1] * v.h[1][i2] * w1;
        out.second(k, 5) = 0.0;
      }
    }
  }
  return out;
}

PlaneValues CubicHermiteLinear::evaluate(const Eigen::Vector2d& xi, unsigned updates) {
  PlaneValues out;
  out.updated = updates;
  const int mo = max_order(updates);
  const Hermite1D u(xi[0], mo);
  const Linear1D w(xi[1]);
  for (int n = 0; n < 4; ++n) {
    const int a = n & 1, c = n >> 1;
    for (int d = 0; d < 2; ++d) {
      const int k = 2 * n + d;
      const int i1 = 2 * a + d;
      if (updates & kValues) out.value[k] = u.h[0][i1] * w.l[0][c];
      if (updates & kFirst) {
        out.first(k, 0) = u.h[1][i1] * w.l[0][c];
        out.first(k, 1) = u.h[0][i1] * w.l[1][c];
      }
      if (updates & kSecond) {
        out.second(k, 0) = u.h[2][i1] * w.l[0][c];
        out.second(k, 1) = u.h[1][i1] * w.l[1][c];
        out.second(k, 2) = 0.0;
      }
    }
  }
  return out;
}

}  // namespace sf::basis
