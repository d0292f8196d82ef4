#include "gsa/digitise/camera.hpp"

#include <Eigen/LU>
#include <cmath>
#include <sstream>

#include "common/core/error.hpp"
#include "common/io/json.hpp"

namespace sf::gsa::digitise {

Vec2 Camera::distort(const Vec2& xn, Mat2* jacobian) const {
  const Distortion& d = distortion;
  const double x = xn.x(), y = xn.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
  const Vec2 out(x * radial + 2.0 * d.p1 * x * y + d.p2 * (r2 + 2.0 * x * x),
                 y * radial + d.p1 * (r2 + 2.0 * y * y) + 2.0 * d.p2 * x * y);
  if (jacobian) {
    const double dr = d.k1 + r2 * (2.0 * d.k2 + 3.0 * d.k3 * r2);  // d radial / d r^2
    const double cross = 2.0 * x * y * dr + 2.0 * d.p1 * x + 2.0 * d.p2 * y;
    *jacobian << radial + 2.0 * x * x * dr + 2.0 * d.p1 * y + 6.0 * d.p2 * x, cross,  //
        cross, radial + 2.0 * y * y * dr + 6.0 * d.p1 * y + 2.0 * d.p2 * x;
  }
  return out;
}

Vec2 Camera::undistort(const Vec2& xd) const {
  if (distortion.is_zero()) return xd;
  Vec2 x = xd;
  Mat2 J;
  for (int it = 0; it < 30; ++it) {
    const Vec2 r = distort(x, &J) - xd;
    if (r.squaredNorm() < 1e-30) break;
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-12)) break;
    x -= J.inverse() * r;
  }
  return x;
}

Vec2 Camera::project(const Vec3& X) const {
  const Vec3 xc = to_camera(X);
  const Vec2 xd = distort(Vec2(xc.x() / xc.z(), xc.y() / xc.z()));
  return Vec2(fx * xd.x() + cx, fy * xd.y() + cy);
}

Vec2 Camera::project(const Vec3& X, Eigen::Matrix<double, 2, 3>* jacobian) const {
  const Vec3 xc = to_camera(X);
  const double iz = 1.0 / xc.z();
  const Vec2 xn(xc.x() * iz, xc.y() * iz);
  Mat2 Jd;
  const Vec2 xd = distort(xn, &Jd);
  if (jacobian) {
    Eigen::Matrix<double, 2, 3> dn;
    dn << iz, 0, -xn.x() * iz, 0, iz, -xn.y() * iz;
    Mat2 F = Mat2::Zero();
    F(0, 0) = fx;
    F(1, 1) = fy;
    *jacobian = F * Jd * dn * R;
  }
  return Vec2(fx * xd.x() + cx, fy * xd.y() + cy);
}

Vec2 Camera::pixel_to_normalised(const Vec2& uv) const {
  return undistort(Vec2((uv.x() - cx) / fx, (uv.y() - cy) / fy));
}

Vec2 Camera::normalised_to_pixel(const Vec2& xn) const {
  const Vec2 xd = distort(xn);
  return Vec2(fx * xd.x() + cx, fy * xd.y() + cy);
}

Vec3 Camera::ray(const Vec2& uv) const {
  const Vec2 xn = pixel_to_normalised(uv);
  return (R.transpose() * Vec3(xn.x(), xn.y(), 1.0)).normalized();
}

Mat3 essential_matrix(const Camera& a, const Camera& b) {
  // x_b = R_ab x_a + t_ab (camera a -> camera b).
  const Mat3 Rab = b.R * a.R.transpose();
  const Vec3 tab = b.t - Rab * a.t;
  Mat3 tx;
  tx << 0, -tab.z(), tab.y(), tab.z(), 0, -tab.x(), -tab.y(), tab.x(), 0;
  return tx * Rab;
}

double epipolar_distance_px(const Mat3& E, const Vec2& xa, const Vec2& xb, const Camera& b) {
  const Vec3 line = E * Vec3(xa.x(), xa.y(), 1.0);
  // Distance in normalised units, then scaled to b's pixels (line direction weighted by f).
  const double num = line.dot(Vec3(xb.x(), xb.y(), 1.0));
  const double gx = line.x() * b.fy, gy = line.y() * b.fx;  // the line in pixel units
  const double n = std::hypot(gx, gy);
  return n > 0 ? std::abs(num) * b.fx * b.fy / n : std::abs(num) * b.focal();
}

// ---------------------------------------------------------------------------------------
// Rig files

namespace {

[[noreturn]] void bad(const std::string& file, const std::string& key, const std::string& what) {
  throw InputError(file + ": " + key + ": " + what);
}

double number(const nlohmann::json& j, const char* key, const std::string& file, const std::string& where,
              bool positive = false) {
  if (!j.contains(key)) bad(file, where + key, "missing");
  const auto& v = j.at(key);
  if (!v.is_number()) bad(file, where + key, "expected a number, found " + v.dump());
  const double x = v.get<double>();
  if (!std::isfinite(x) || (positive && !(x > 0)))
    bad(file, where + key,
        std::string("expected a ") + (positive ? "positive " : "finite ") + "number, found " + v.dump());
  return x;
}

}  // namespace

nlohmann::json rig_to_json(const Rig& rig) {
  nlohmann::json j;
  j["format"] = "sheetform camera rig";
  j["version"] = 1;
  j["units"] = rig.units;
  j["model"] =
      "pinhole + Brown-Conrady (OpenCV k1 k2 p1 p2 k3); x_cam = R X + t; pixel (0,0) = centre of the "
      "top-left pixel";
  nlohmann::json cams = nlohmann::json::array();
  for (const Camera& c : rig.cameras) {
    nlohmann::json cj;
    cj["name"] = c.name;
    cj["image_size"] = {c.width, c.height};
    cj["fx"] = c.fx;
    cj["fy"] = c.fy;
    cj["cx"] = c.cx;
    cj["cy"] = c.cy;
    cj["distortion"] = {{"k1", c.distortion.k1},
                        {"k2", c.distortion.k2},
                        {"p1", c.distortion.p1},
                        {"p2", c.distortion.p2},
                        {"k3", c.distortion.k3}};
    cj["R"] = io::to_json(c.R);
    cj["t"] = {c.t.x(), c.t.y(), c.t.z()};
    cams.push_back(cj);
  }
  j["cameras"] = cams;
  if (!rig.calibration_info.is_null()) j["calibration"] = rig.calibration_info;
  return j;
}

Rig rig_from_json(const nlohmann::json& j, const std::string& file) {
  if (!j.is_object()) bad(file, "(top level)", "expected a JSON object with a 'cameras' array");
  Rig rig;
  if (j.contains("units")) {
    if (!j.at("units").is_string()) bad(file, "units", "expected a string such as \"mm\"");
    rig.units = j.at("units").get<std::string>();
  }
  if (!j.contains("cameras") || !j.at("cameras").is_array() || j.at("cameras").empty())
    bad(file, "cameras", "expected a non-empty array of cameras");
  const auto& cams = j.at("cameras");
  for (std::size_t k = 0; k < cams.size(); ++k) {
    const std::string where = "cameras[" + std::to_string(k) + "].";
    const auto& cj = cams[k];
    if (!cj.is_object()) bad(file, "cameras[" + std::to_string(k) + "]", "expected an object");
    Camera c;
    c.name =
        cj.contains("name") && cj.at("name").is_string() ? cj.at("name").get<std::string>() : "cam" + std::to_string(k);
    if (!cj.contains("image_size") || !cj.at("image_size").is_array() || cj.at("image_size").size() != 2 ||
        !cj.at("image_size")[0].is_number_integer() || !cj.at("image_size")[1].is_number_integer() ||
        cj.at("image_size")[0].get<long>() < 1 || cj.at("image_size")[1].get<long>() < 1)
      bad(file, where + "image_size", "expected [width, height] in pixels (positive integers)");
    c.width = cj.at("image_size")[0].get<int>();
    c.height = cj.at("image_size")[1].get<int>();
    c.fx = number(cj, "fx", file, where, true);
    c.fy = number(cj, "fy", file, where, true);
    c.cx = number(cj, "cx", file, where);
    c.cy = number(cj, "cy", file, where);
    if (cj.contains("distortion")) {
      const auto& d = cj.at("distortion");
      if (!d.is_object()) bad(file, where + "distortion", "expected an object with k1, k2, p1, p2, k3");
      const std::string dw = where + "distortion.";
      for (const auto& [key, value] : d.items())
        if (key != "k1" && key != "k2" && key != "p1" && key != "p2" && key != "k3")
          bad(file, dw + key, "unknown coefficient (the model has k1, k2, p1, p2, k3)");
      auto opt = [&](const char* key) { return d.contains(key) ? number(d, key, file, dw) : 0.0; };
      c.distortion = {opt("k1"), opt("k2"), opt("p1"), opt("p2"), opt("k3")};
    }
    if (cj.contains("R")) {
      const auto& r = cj.at("R");
      bool ok = r.is_array() && r.size() == 3;
      for (std::size_t a = 0; ok && a < 3; ++a) {
        ok = r[a].is_array() && r[a].size() == 3;
        for (std::size_t b = 0; ok && b < 3; ++b) {
          ok = r[a][b].is_number();
          if (ok) c.R(a, b) = r[a][b].get<double>();
        }
      }
      if (!ok) bad(file, where + "R", "expected a 3 x 3 rotation matrix as three rows of three numbers");
      const double err = (c.R * c.R.transpose() - Mat3::Identity()).cwiseAbs().maxCoeff();
      if (!(err < 1e-6) || !(c.R.determinant() > 0))
        bad(file, where + "R", "not a rotation matrix (R R^T differs from I by " + std::to_string(err) + ")");
    }
    if (cj.contains("t")) {
      const auto& tv = cj.at("t");
      bool ok = tv.is_array() && tv.size() == 3;
      for (std::size_t a = 0; ok && a < 3; ++a) {
        ok = tv[a].is_number();
        if (ok) c.t(a) = tv[a].get<double>();
      }
      if (!ok) bad(file, where + "t", "expected a translation [tx, ty, tz] in the rig's units");
    }
    rig.cameras.push_back(c);
  }
  if (j.contains("calibration")) rig.calibration_info = j.at("calibration");
  return rig;
}

Rig read_rig(const std::string& path) { return rig_from_json(io::read_json(path), path); }

void write_rig(const std::string& path, const Rig& rig) { io::write_json(path, rig_to_json(rig)); }

}  // namespace sf::gsa::digitise
