#pragma once
// Contact of a surface of one body (slave: its contact points) with a surface of another
// body (master): the SurfaceContact (forming/contact/surface_contact.hpp) whose partner
// at a slave point x_s is the closest point of the master surface, x_m(zeta), on its
// current geometry, with the gap along the master face's outward normal,
// g = (x_s - x_m) . n_m. Ply-ply contact in a laminate is the top face of ply k against
// the bottom face of ply k + 1; a diaphragm is one more body.
//
// Search, rebuilt at every evaluation as the surfaces move: every master face's box
// (the hull of its Bezier control points, forming/contact/contact_surface.hpp) goes into
// a bounding-volume tree (forming/contact/box_tree.hpp); a slave point queries the faces
// whose box holds it within the search distance (default: the two plies' thicknesses
// summed), and each candidate face is projected on (forming/contact/face_projection.hpp);
// the closest wins. A point whose closest point lies on a free edge of the master
// surface with the gradient still pushing outward (the point is beside the master, not
// opposite it) has no partner. Cost per evaluation: O(F log F) for the tree of F master
// faces plus O(P (log F + c)) for P slave points with c candidates each (c ~ 1..4 when
// faces are larger than the search distance); never all pairs.
//
// Units: mm, N, s.
#include <string>

#include "forming/contact/surface_contact.hpp"

namespace sf::forming {

class BodyContact final : public SurfaceContact {
 public:
  // Throws sf::InputError when both surfaces belong to the same body.
  BodyContact(std::string name, const Model& model, ContactSurface slave, ContactSurface master,
              ContactOptions options);

  bool symmetric() const override { return !options().friction.active() && !options().half_pass; }
  std::string describe() const override;
  double search_reach() const override { return reach_; }
  const ContactSurface& master() const { return master_; }

 private:
  struct Search;
  std::unique_ptr<Prepared> prepare(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                                    const VecX* rates, const VecX* previous) const override;
  bool find_partner(const Prepared& prepared, const Vec3& xs, PointKinematics& k, Partner& partner) const override;

  ContactSurface master_;
  double reach_ = 0.0;  // search distance, mm
};

}  // namespace sf::forming
