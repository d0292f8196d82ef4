#include "forming/contact/rigid_tool.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/core/error.hpp"

namespace sf::forming {
namespace {

std::string vec(const Vec3& v) {
  std::ostringstream os;
  os << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}

}  // namespace

ToolMotion ToolMotion::ramped(const Vec3& value, Ramp ramp, double duration) {
  if (!value.allFinite()) throw InputError("tool motion displacement: expected finite components (mm)");
  if (!(std::isfinite(duration) && duration > 0.0)) {
    std::ostringstream os;
    os << "tool motion duration: expected a positive time (s), found " << duration;
    throw InputError(os.str());
  }
  ToolMotion m;
  m.kind_ = Kind::kRamped;
  m.value_ = value;
  m.ramp_ = ramp;
  m.duration_ = duration;
  return m;
}

ToolMotion ToolMotion::constant_velocity(const Vec3& velocity) {
  if (!velocity.allFinite()) throw InputError("tool motion velocity: expected finite components (mm/s)");
  ToolMotion m;
  m.kind_ = Kind::kVelocity;
  m.value_ = velocity;
  return m;
}

ToolMotion ToolMotion::table(std::vector<std::pair<double, Vec3>> points) {
  if (points.empty()) throw InputError("tool motion table: expected at least one [t, dx, dy, dz] row");
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!std::isfinite(points[i].first) || !points[i].second.allFinite())
      throw InputError("tool motion table row " + std::to_string(i + 1) + ": expected finite values");
    if (i > 0 && !(points[i].first > points[i - 1].first))
      throw InputError("tool motion table row " + std::to_string(i + 1) + ": times must increase");
  }
  ToolMotion m;
  m.kind_ = Kind::kTable;
  m.table_ = std::move(points);
  return m;
}

Vec3 ToolMotion::displacement(double t) const {
  switch (kind_) {
    case Kind::kFixed:
      return Vec3::Zero();
    case Kind::kRamped:
      return value_ * ramp_value(ramp_, t / duration_);
    case Kind::kVelocity:
      return value_ * t;
    case Kind::kTable: {
      if (t <= table_.front().first) return table_.front().second;
      if (t >= table_.back().first) return table_.back().second;
      const auto it = std::upper_bound(table_.begin(), table_.end(), t,
                                       [](double v, const std::pair<double, Vec3>& p) { return v < p.first; });
      const auto& [t1, d1] = *it;
      const auto& [t0, d0] = *(it - 1);
      return d0 + (d1 - d0) * ((t - t0) / (t1 - t0));
    }
  }
  return Vec3::Zero();
}

Vec3 ToolMotion::velocity(double t) const {
  switch (kind_) {
    case Kind::kFixed:
      return Vec3::Zero();
    case Kind::kRamped:
      return value_ * ramp_rate(ramp_, t / duration_) / duration_;
    case Kind::kVelocity:
      return value_;
    case Kind::kTable: {
      if (table_.size() < 2 || t < table_.front().first || t >= table_.back().first) return Vec3::Zero();
      const auto it = std::upper_bound(table_.begin(), table_.end(), t,
                                       [](double v, const std::pair<double, Vec3>& p) { return v < p.first; });
      const auto& [t1, d1] = *it;
      const auto& [t0, d0] = *(it - 1);
      return (d1 - d0) / (t1 - t0);
    }
  }
  return Vec3::Zero();
}

std::string ToolMotion::describe() const {
  std::ostringstream os;
  switch (kind_) {
    case Kind::kFixed:
      return "fixed";
    case Kind::kRamped:
      os << "ramped " << vec(value_) << " mm over " << duration_ << " s (" << to_string(ramp_) << ")";
      break;
    case Kind::kVelocity:
      os << "constant velocity " << vec(value_) << " mm/s";
      break;
    case Kind::kTable:
      os << "table of " << table_.size() << " points";
      break;
  }
  return os.str();
}

}  // namespace sf::forming
