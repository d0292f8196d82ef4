#pragma once
// Calibrated pinhole cameras with Brown-Conrady lens distortion, and camera rigs.
//
// Conventions (the same as OpenCV's, so calibrations from OpenCV read as they are):
//
//   world point X (mm)  --pose-->  camera point x_c = R X + t  (x right, y down, z forward)
//   normalised          x = x_c / z_c,  y = y_c / z_c
//   distorted           r^2 = x^2 + y^2,  radial = 1 + k1 r^2 + k2 r^4 + k3 r^6
//                       x_d = x radial + 2 p1 x y + p2 (r^2 + 2 x^2)
//                       y_d = y radial + p1 (r^2 + 2 y^2) + 2 p2 x y
//   pixel               u = fx x_d + cx,  v = fy y_d + cy
//
// Pixel coordinates have their origin at the CENTRE of the top-left pixel: pixel (c, r)
// covers [c - 0.5, c + 0.5] x [r - 0.5, r + 0.5]; u grows to the right, v downward.
//
// A rig is a list of cameras whose poses share one world frame; `gsa calibrate` writes
// rigs whose world frame is camera 0's (R = I, t = 0 for camera 0). The rig file format
// (JSON) is documented in docs/digitise.md.

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/core/types.hpp"

namespace sf::gsa::digitise {

// OpenCV's five-coefficient model (k1, k2, p1, p2, k3); all zero = no distortion.
struct Distortion {
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  bool is_zero() const { return k1 == 0 && k2 == 0 && p1 == 0 && p2 == 0 && k3 == 0; }
};

struct Camera {
  std::string name;           // e.g. "cam0"
  int width = 0, height = 0;  // image size, pixels
  double fx = 1, fy = 1;      // focal lengths, pixels
  double cx = 0, cy = 0;      // principal point, pixels
  Distortion distortion;
  Mat3 R = Mat3::Identity();  // world -> camera rotation
  Vec3 t = Vec3::Zero();      // world -> camera translation (mm)

  // Camera centre in the world frame (mm).
  Vec3 centre() const { return -R.transpose() * t; }
  // Point in camera coordinates.
  Vec3 to_camera(const Vec3& X) const { return R * X + t; }
  // True when X lies in front of the camera (z_c > 0).
  bool in_front(const Vec3& X) const { return to_camera(X).z() > 0; }

  // Normalised (undistorted) -> distorted normalised coordinates; `jacobian` (optional)
  // receives d(distorted)/d(normalised).
  Vec2 distort(const Vec2& xn, Mat2* jacobian = nullptr) const;
  // Inverse of distort() by Newton's method (to 1e-14); valid inside the image and a
  // little beyond. Returns the best estimate if it does not converge (strong distortion
  // far outside the image), which the callers never need.
  Vec2 undistort(const Vec2& xd) const;

  // World point -> pixel (with distortion). X must be in front of the camera.
  Vec2 project(const Vec3& X) const;
  // Same, with d(pixel)/d(X) (2 x 3).
  Vec2 project(const Vec3& X, Eigen::Matrix<double, 2, 3>* jacobian) const;
  // Pixel -> undistorted normalised coordinates (the ray through the pixel is
  // R^T (x, y, 1) from centre()).
  Vec2 pixel_to_normalised(const Vec2& uv) const;
  // Undistorted normalised coordinates -> pixel.
  Vec2 normalised_to_pixel(const Vec2& xn) const;
  // Unit ray direction through a pixel, world frame.
  Vec3 ray(const Vec2& uv) const;

  // Mean focal length (pixels per unit of normalised coordinate).
  double focal() const { return 0.5 * (fx + fy); }
};

// Essential matrix of the pair (a, b) in undistorted normalised coordinates:
// x_b^T E x_a = 0 for homogeneous x = (x, y, 1) of the same world point.
Mat3 essential_matrix(const Camera& a, const Camera& b);
// Distance of b's observation from the epipolar line of a's, both given as undistorted
// normalised coordinates, in b's undistorted pixels (the lens's local scale, a few per cent
// at the image's edges, is not applied).
double epipolar_distance_px(const Mat3& E, const Vec2& xa, const Vec2& xb, const Camera& b);

struct Rig {
  std::vector<Camera> cameras;
  std::string units = "mm";
  nlohmann::json calibration_info;  // what produced the rig (target, errors); free form

  Index n_cameras() const { return static_cast<Index>(cameras.size()); }
};

// Reads a rig file. Throws sf::InputError "PATH: ..." naming the key that is missing or
// wrong, e.g. "rig.json: cameras[1].fx: expected a positive number".
Rig read_rig(const std::string& path);
// The rig as JSON (the format of docs/digitise.md), and written atomically to a file.
nlohmann::json rig_to_json(const Rig& rig);
Rig rig_from_json(const nlohmann::json& j, const std::string& name_for_messages);
void write_rig(const std::string& path, const Rig& rig);

}  // namespace sf::gsa::digitise
