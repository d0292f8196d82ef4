#include "forming/output/sampling.hpp"

#include <Eigen/LU>

#include "common/basis/hermite.hpp"

namespace sf::forming {

BrickPoint sample_brick(const BrickParams& Xe, const BrickParams& xe, const Vec3& xi) {
  const basis::BrickValues v = basis::BicubicHermiteLinear::evaluate(xi, basis::kValues | basis::kFirst);
  BrickPoint s;
  s.X = Xe.transpose() * v.value;
  s.x = xe.transpose() * v.value;
  const Mat3 G = Xe.transpose() * v.first;
  const Mat3 g = xe.transpose() * v.first;
  s.F = g * G.inverse();
  return s;
}

}  // namespace sf::forming
