#pragma once
// Basic fixed-size and dynamic types used across the suite.

#include <Eigen/Core>
#include <cstdint>

namespace sf {

using Index = std::int64_t;

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat2 = Eigen::Matrix2d;
using Mat3 = Eigen::Matrix3d;
using Mat32 = Eigen::Matrix<double, 3, 2>;
using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;
// Row-major n x 3 point arrays (one point per row, same layout as a CSV file).
using Points3 = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace sf
