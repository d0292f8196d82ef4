#pragma once
// Contact of a body's surface with a rigid tool (forming/contact/rigid_tool.hpp): the
// SurfaceContact (forming/contact/surface_contact.hpp) whose partner at a slave point x_s
// is the tool's gap function at the context's time, g = gap(x_s - d(t)), with the tool's
// velocity d'(t) (dynamic runs) or (d(t) - d(t_prev)) / dt (quasi-static runs with a
// process time) for friction.
//
// The tool's reaction, reactions(), is the force the bodies exert on it:
//   F_tool = - sum over contact points of w (p n + t_T),
// the pressure pushing the surface along the tool's outward normal n and the friction
// traction t_T = -c v_T on the surface; a punch pressing down (-z) on a ply sees
// F_tool,z > 0.
//
// Units: mm, N, s.
#include <string>

#include "forming/contact/rigid_tool.hpp"
#include "forming/contact/surface_contact.hpp"

namespace sf::forming {

class ToolContact final : public SurfaceContact {
 public:
  ToolContact(std::string name, const Model& model, ContactSurface slave, RigidTool tool, ContactOptions options);

  bool symmetric() const override { return tool_.shape->symmetric() && !options().friction.active(); }
  std::vector<ToolReaction> reactions(const Eigen::Ref<const VecX>& x,
                                      const InteractionContext& context) const override;
  std::string describe() const override;
  double search_reach() const override { return reach_; }
  const RigidTool& tool() const { return tool_; }

 private:
  struct ToolState;
  std::unique_ptr<Prepared> prepare(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                                    const VecX* rates, const VecX* previous) const override;
  bool find_partner(const Prepared& prepared, const Vec3& xs, PointKinematics& k, Partner& partner) const override;

  RigidTool tool_;
  double reach_ = 0.0;  // mm: points farther outside the tool have no partner
};

}  // namespace sf::forming
