#pragma once
// A rigid tool: a shape at rest (forming/contact/tool_shape.hpp) translated by a
// prescribed motion d(t), and its name (history.csv columns, outputs).
//
// Motions (the time t is in s: the dynamic run's time, or in a quasi-static run the
// process time lambda * process_time, docs/forming.md):
//   fixed              d = 0;
//   ramped             d = value ramp(t / duration) (linear or smooth, forming/model/ramp.hpp),
//                      held at `value` after `duration`;
//   constant velocity  d = v t;
//   table              piecewise linear through (t_i, d_i), t_i ascending, held at the
//                      first and last d_i outside the table.
// The tool's surface at time t is {x : shape.gap(x - d(t)) = 0}; its velocity d'(t) is
// what friction measures slip against.
//
// Units: mm, s.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common/core/types.hpp"
#include "forming/contact/tool_shape.hpp"
#include "forming/model/ramp.hpp"

namespace sf::forming {

class ToolMotion {
 public:
  static ToolMotion fixed() { return ToolMotion(); }
  // Throws sf::InputError for a non-positive or non-finite duration or a non-finite value.
  static ToolMotion ramped(const Vec3& value, Ramp ramp, double duration);
  static ToolMotion constant_velocity(const Vec3& velocity);
  // Throws sf::InputError unless the times are finite and strictly ascending (>= 1 point).
  static ToolMotion table(std::vector<std::pair<double, Vec3>> points);

  Vec3 displacement(double t) const;  // mm
  Vec3 velocity(double t) const;      // mm/s
  bool moves() const { return kind_ != Kind::kFixed; }
  // One line for summary.json, e.g. "ramped [0, 0, -10] mm over 1 s (smooth)".
  std::string describe() const;

 private:
  enum class Kind { kFixed, kRamped, kVelocity, kTable };
  Kind kind_ = Kind::kFixed;
  Vec3 value_ = Vec3::Zero();  // ramped: final displacement; velocity: mm/s
  Ramp ramp_ = Ramp::kLinear;
  double duration_ = 1.0;
  std::vector<std::pair<double, Vec3>> table_;
};

struct RigidTool {
  std::string name;
  std::shared_ptr<const ToolShape> shape;
  ToolMotion motion;

  // The tool's gap function at time t (the shape evaluated at x - d(t)).
  ToolPoint at(const Vec3& x, double t) const { return shape->evaluate(x - motion.displacement(t)); }
};

}  // namespace sf::forming
