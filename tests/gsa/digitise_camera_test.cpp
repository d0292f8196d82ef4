// Camera model and rig files (gsa/digitise/camera.hpp): distortion inverse and Jacobians
// against finite differences, epipolar geometry of exact correspondences, the rig file
// round trip and its error messages.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "common/core/error.hpp"
#include "gsa/digitise/camera.hpp"
#include "tests/common/io_test_util.hpp"
#include "tests/common/tolerances.hpp"

namespace sf::gsa::digitise {
namespace {

using ::testing::HasSubstr;

Camera test_camera() {
  Camera c;
  c.name = "c";
  c.width = 1632;
  c.height = 1224;
  c.fx = 2400;
  c.fy = 2403;
  c.cx = 820.3;
  c.cy = 607.9;
  c.distortion = {-0.12, 0.09, 4e-4, -3e-4, 0.02};
  c.R = Eigen::AngleAxisd(0.3, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  c.t = Vec3(12, -30, 420);
  return c;
}

TEST(DigitiseCamera, DistortionProjectionAndRays) {
  {  // undistort inverts distort across the image
    const Camera c = test_camera();
    double worst = 0;
    for (double u = 0; u <= c.width; u += 136)
      for (double v = 0; v <= c.height; v += 102) {
        const Vec2 xd((u - c.cx) / c.fx, (v - c.cy) / c.fy);
        worst = std::max(worst, (c.distort(c.undistort(xd)) - xd).norm());
      }
    EXPECT_LT(worst, 1e-13);
  }
  {  // distortion jacobian matches finite differences
    const Camera c = test_camera();
    for (const Vec2& x : {Vec2(0.1, -0.2), Vec2(-0.3, 0.25), Vec2(0.0, 0.0)}) {
      Mat2 J;
      c.distort(x, &J);
      for (int k = 0; k < 2; ++k) {
        Vec2 h = Vec2::Zero();
        h(k) = sf::test::kFdStep;
        const Vec2 fd = (c.distort(x + h) - c.distort(x - h)) / (2 * sf::test::kFdStep);
        EXPECT_LT((J.col(k) - fd).norm(), sf::test::kFdFirst) << "column " << k << " at " << x.transpose();
      }
    }
  }
  {  // projection jacobian matches finite differences
    const Camera c = test_camera();
    const Vec3 X(20, 35, -10);
    Eigen::Matrix<double, 2, 3> J;
    c.project(X, &J);
    for (int k = 0; k < 3; ++k) {
      Vec3 h = Vec3::Zero();
      h(k) = 1e-4;
      const Vec2 fd = (c.project(X + h) - c.project(X - h)) / 2e-4;
      EXPECT_LT((J.col(k) - fd).norm(), 1e-6 * J.norm()) << "column " << k;
    }
  }
  {  // pixel ray passes through the point
    const Camera c = test_camera();
    const Vec3 X(-40, 25, 8);
    const Vec3 d = c.ray(c.project(X));
    const Vec3 to = (X - c.centre()).normalized();
    EXPECT_LT((d - to).norm(), 1e-12);
  }
}

TEST(DigitiseCamera, EpipolarDistanceIsZeroForTheSamePointAndGrowsOffIt) {
  const Camera a = test_camera();
  Camera b = test_camera();
  b.R = Eigen::AngleAxisd(-0.2, Vec3(0.3, 1, 0).normalized()).toRotationMatrix();
  b.t = Vec3(-150, 10, 430);
  const Mat3 E = essential_matrix(a, b);
  std::mt19937 rng(sf::test::kSeed);
  std::uniform_real_distribution<double> u(-60, 60);
  for (int k = 0; k < 20; ++k) {
    const Vec3 X(u(rng), u(rng), 0.2 * u(rng));
    const Vec2 xa = a.pixel_to_normalised(a.project(X)), xb = b.pixel_to_normalised(b.project(X));
    EXPECT_LT(epipolar_distance_px(E, xa, xb, b), 1e-8);
  }
  // A pixel moved across the epipolar line by 3 px is 3 px off it.
  const Vec3 X(5, 7, 1);
  const Vec2 pb = b.project(X), pa = a.project(X);
  const Vec3 line = E * Vec3(a.pixel_to_normalised(pa).x(), a.pixel_to_normalised(pa).y(), 1.0);
  const Vec2 xb = b.pixel_to_normalised(pb);
  // The line's normal direction in b's pixels, from two points on it.
  const Vec2 q1 = b.normalised_to_pixel(xb), q2 = b.normalised_to_pixel(xb + 1e-4 * Vec2(-line.y(), line.x()));
  const Vec2 along = (q2 - q1).normalized(), across(-along.y(), along.x());
  // (Distances are measured in undistorted pixels: within the lens's local scale change.)
  EXPECT_NEAR(epipolar_distance_px(E, a.pixel_to_normalised(pa), b.pixel_to_normalised(pb + 3.0 * across), b), 3.0,
              0.1);
}

TEST(DigitiseCamera, RigFilesRoundTripAndNameBadKeys) {
  {  // rig file round trips
    io::test::ScratchDir dir;
    Rig rig;
    rig.cameras = {test_camera(), test_camera()};
    rig.cameras[1].name = "right";
    rig.cameras[1].t = Vec3(-200, 0, 10);
    write_rig(dir.file("rig.json"), rig);
    const Rig back = read_rig(dir.file("rig.json"));
    ASSERT_EQ(back.n_cameras(), 2);
    EXPECT_EQ(back.cameras[1].name, "right");
    for (int k = 0; k < 2; ++k) {
      const Camera &a = rig.cameras[k], &b = back.cameras[k];
      EXPECT_EQ(a.width, b.width);
      EXPECT_DOUBLE_EQ(a.fx, b.fx);
      EXPECT_DOUBLE_EQ(a.distortion.k3, b.distortion.k3);
      EXPECT_LT((a.R - b.R).norm(), 1e-15);
      EXPECT_LT((a.t - b.t).norm(), 1e-12);
    }
  }
  {  // rig file errors name the key
    io::test::ScratchDir dir;
    const auto bad = [&](const std::string& text) {
      io::test::write_text(dir.file("r.json"), text);
      return io::test::message_of<InputError>([&] { read_rig(dir.file("r.json")); });
    };
    EXPECT_THAT(bad(R"({"cameras": []})"), HasSubstr("cameras"));
    EXPECT_THAT(bad(R"({"cameras": [{"image_size": [10, 10], "fx": -1, "fy": 1, "cx": 0, "cy": 0}]})"),
                HasSubstr("cameras[0].fx"));
    EXPECT_THAT(bad(R"({"cameras": [{"image_size": [10], "fx": 1, "fy": 1, "cx": 0, "cy": 0}]})"),
                HasSubstr("image_size"));
    EXPECT_THAT(bad(R"({"cameras": [{"image_size": [10, 10], "fx": 1, "fy": 1, "cx": 0, "cy": 0,
                       "R": [[1,0,0],[0,1,0],[0,0,2]]}]})"),
                HasSubstr("rotation"));
    EXPECT_THAT(bad(R"({"cameras": [{"image_size": [10, 10], "fx": 1, "fy": 1, "cx": 0, "cy": 0,
                       "distortion": {"k9": 1}}]})"),
                HasSubstr("distortion.k9"));
    EXPECT_THAT(io::test::message_of<InputError>([&] { read_rig(dir.file("missing.json")); }),
                HasSubstr("missing.json"));
  }
}

}  // namespace
}  // namespace sf::gsa::digitise
