#include "forming/contact/tool_contact.hpp"

#include <utility>

namespace sf::forming {

struct ToolContact::ToolState : Prepared {
  double time = 0.0;
  Vec3 displacement = Vec3::Zero();  // d(t)
  Vec3 velocity = Vec3::Zero();      // rate of d
  Vec3 moved = Vec3::Zero();         // d(t) - d(t_prev)
};

ToolContact::ToolContact(std::string name, const Model& model, ContactSurface slave, RigidTool tool,
                         ContactOptions options)
    : SurfaceContact(std::move(name), model, std::move(slave), options), tool_(std::move(tool)) {
  reach_ = this->options().search_distance > 0.0 ? this->options().search_distance : this->slave().thickness();
}

std::unique_ptr<SurfaceContact::Prepared> ToolContact::prepare(const Eigen::Ref<const VecX>&,
                                                               const InteractionContext& context, const VecX* rates,
                                                               const VecX* previous) const {
  auto s = std::make_unique<ToolState>();
  s->time = context.time;
  s->displacement = tool_.motion.displacement(context.time);
  if (previous) s->moved = s->displacement - tool_.motion.displacement(context.previous_time);
  if (rates) {
    if (context.velocity)
      s->velocity = tool_.motion.velocity(context.time);
    else
      s->velocity = s->moved / (context.time - context.previous_time);
  }
  return s;
}

bool ToolContact::find_partner(const Prepared& prepared, const Vec3& xs, PointKinematics& k, Partner& partner) const {
  const auto& s = static_cast<const ToolState&>(prepared);
  const ToolPoint t = tool_.shape->evaluate(xs - s.displacement);
  if (!t.in_front || t.gap > reach_) return false;
  k.tool = true;
  k.gap = t.gap;
  k.normal = t.normal;
  k.gap_gradient = t.gap_gradient;
  k.dn_dx = t.normal_gradient;
  partner.velocity = s.velocity;
  partner.displacement = s.moved;
  return true;
}

std::vector<ToolReaction> ToolContact::reactions(const Eigen::Ref<const VecX>& x,
                                                 const InteractionContext& context) const {
  ToolReaction r;
  r.tool = tool_.name;
  r.displacement = tool_.motion.displacement(context.time);
  for (const ContactPointRecord& p : sample(x, context))
    if (p.partner) r.force -= p.weight * (p.pressure * p.normal + p.shear);
  return {r};
}

std::string ToolContact::describe() const {
  const BrickFace f = slave().face(0).face;
  const char* side = f == BrickFace::kTop ? "top" : f == BrickFace::kBottom ? "bottom" : "side";
  return "body " + std::to_string(slave().body()) + " " + side + " against tool '" + tool_.name + "' (" +
         tool_.shape->kind() + ", " + tool_.motion.describe() + ")";
}

}  // namespace sf::forming
