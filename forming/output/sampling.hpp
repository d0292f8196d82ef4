#pragma once
// Sampling a ply brick at a point for the outputs: reference and current position and
// the deformation gradient at xi in [0,1]^3 (xi3 = 0 bottom face, 1 top face).
#include "common/core/types.hpp"
#include "forming/element/element.hpp"

namespace sf::forming {

struct BrickPoint {
  Vec3 X = Vec3::Zero();  // reference position, mm
  Vec3 x = Vec3::Zero();  // current position, mm
  Mat3 F = Mat3::Identity();
};

// Xe, xe: the brick's reference and current xi-parameters (PlyMesh::element_parameters).
BrickPoint sample_brick(const BrickParams& Xe, const BrickParams& xe, const Vec3& xi);

}  // namespace sf::forming
