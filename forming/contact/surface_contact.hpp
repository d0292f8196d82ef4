#pragma once
// Contact of a surface of a body against a partner (a rigid tool, forming/contact/
// tool_contact.hpp, or a surface of another body, forming/contact/body_contact.hpp), as
// an Interaction (forming/model/interaction.hpp): "a surface of a body" is the slave
// side of every pair, so ply-ply, ply-tool and, with diaphragms as bodies, ply-diaphragm
// and diaphragm-tool pairs are all the same two classes.
//
// Contact points: an n x n Gauss grid (default 6 x 6, Christie 1997) on every face of
// the slave surface (forming/contact/contact_surface.hpp), with weights w = Gauss weight
// x the reference area element |X,s x X,t|. At each point the partner gives the gap and
// its derivatives (forming/contact/contact_kernel.hpp), the laws the pressure and the
// friction traction (forming/contact/contact_law.hpp), and the point adds its energy,
// force and (consistent) stiffness and damping. One-pass: the slave points are checked
// against the master surface, not the other way round.
//
// Two half-passes (ContactOptions::half_pass, the case key `two_pass`; Sauer and De
// Lorenzis, CMAME 2013): each surface is once the slave, and each pass applies the
// traction at its points to its own slave side only (its tangent keeps the columns of
// the master dofs, the gap depends on them). Each body's contact forces are then
// integrated with its own quadrature, so a uniform pressure across non-matching meshes
// is transmitted exactly (the one-pass scheme integrates the master's functions with
// the slave's points, which is not exact across master element edges). Action and
// reaction then agree only as far as the two passes' pressures agree (to the
// discretisation error); the tangent is unsymmetric. Each pass reports half the
// penalty energy and half the friction dissipation, so the pair's sums are comparable
// with one pass.
//
// State per contact point: the augmented-Lagrangian multiplier lambda (MPa), with
// `stick_slip` the elastic slip e of the slip-distance Coulomb law (mm, contact_law.hpp;
// zero where the point bears no pressure), and the accumulated slip (mm, a vector: the sum over committed steps of the tangential
// relative displacement P J du over the step), and per pair the friction dissipation
// (N mm: the sum over committed steps of w t . du_T, t the friction traction -c v_T:
// in quasi-static runs the step's own traction, whose rate is the difference over the
// step, so the sum is the scheme's exact dissipation; in dynamic runs the mean of the
// tractions at the interval's ends (trapezoidal rule, second order; a run from rest at
// t = 0 takes its start traction with the bodies at rest, a restarted run the end
// traction for its first interval)). Rates come from the context:
// velocities in dynamic runs, finite differences from the previous converged state in
// quasi-static runs with a process time; without either, friction adds nothing.
//
// Units: mm, N, s.
#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/quadrature/gauss.hpp"
#include "forming/contact/contact_kernel.hpp"
#include "forming/contact/contact_law.hpp"
#include "forming/contact/contact_surface.hpp"
#include "forming/model/interaction.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

struct ContactOptions {
  NormalLaw normal;
  FrictionLaw friction;
  int points = 6;                // contact points per face direction (Gauss), 1..12
  double search_distance = 0.0;  // mm; 0: the default (the plies' thicknesses summed)
  // Width of the normal law's rounded kink (contact_law.hpp), mm; 0: the default,
  // 1e-3 x the slave ply's thickness. Wider converges faster where many points sit at the
  // kink (stacked plies): the laminate punch sample's first step takes 15 Newton
  // iterations with 1e-2 x the thickness against 187 (3 cut-backs) with the default,
  // at the price of a pressure S_n band / 8 between plies that merely touch.
  double band = 0.0;
  // Half pass (body contact): the point's traction acts on the slave side only; two half
  // passes, each side once the slave, make the two-half-pass scheme (see header).
  bool half_pass = false;
  // Throws sf::InputError naming the field.
  void validate() const;
};

// What one contact point carries, for outputs and reactions.
struct ContactPointRecord {
  Index face = 0;                 // slave face
  Vec2 st = Vec2::Zero();         // its face coordinates
  Vec3 position = Vec3::Zero();   // current, mm
  bool partner = false;           // has a foot point on the partner within reach
  double gap = 0.0;               // mm (partner only)
  double pressure = 0.0;          // MPa
  Vec3 normal = Vec3::Zero();     // the partner's outward normal there
  Vec3 slip_rate = Vec3::Zero();  // mm/s
  Vec3 shear = Vec3::Zero();      // friction traction on the slave, MPa
  Vec3 slip = Vec3::Zero();       // accumulated (committed), mm
  Vec3 elastic_slip = Vec3::Zero();  // slip-distance Coulomb: the elastic slip e this state commits, mm
  double weight = 0.0;            // mm^2
};

class SurfaceContact : public Interaction {
 public:
  // `model` gives the reference geometry of the slave surface (point weights). Throws
  // sf::InputError for invalid options.
  SurfaceContact(std::string name, const Model& model, ContactSurface slave, ContactOptions options);

  std::string name() const override { return name_; }
  bool needs_velocity() const override { return options_.friction.active(); }
  void add_to(const Eigen::Ref<const VecX>& x, const InteractionContext& context, InteractionSums& sums) const override;
  void commit(const Eigen::Ref<const VecX>& x, const InteractionContext& context) override;
  MultiplierUpdate update_multipliers(const Eigen::Ref<const VecX>& x, const InteractionContext& context) override;
  // Each slave face with each partner face (or the tool: its own dofs) that any of its
  // points finds within the search distance at x (Interaction::pattern_blocks).
  void pattern_blocks(
      const Eigen::Ref<const VecX>& x, const InteractionContext& context,
      const std::function<void(const std::vector<Index>& rows, const std::vector<Index>& cols)>& block) const override;

  // Every contact point at state x, in order (face-major, then the Gauss grid).
  std::vector<ContactPointRecord> sample(const Eigen::Ref<const VecX>& x, const InteractionContext& context) const;
  const ContactSurface& slave() const { return slave_; }
  const ContactOptions& options() const { return options_; }
  Index n_points() const { return slave_.n_faces() * points_per_face(); }
  int points_per_face() const { return options_.points * options_.points; }
  double dissipated() const { return dissipated_; }  // N mm, committed steps
  int multiplier_updates() const { return updates_; }
  // One line for summary.json, e.g. "body 0 top against tool 'punch'".
  virtual std::string describe() const = 0;
  // The search distance (mm): points farther from the partner have none.
  virtual double search_reach() const = 0;
  // The normal law the points use: the options' with the linear tail released at 0.9 x
  // the search distance (NormalLaw::tail_release; contact_law.hpp), so its tie has
  // fallen smoothly to nothing before a point leaves the search.
  NormalLaw normal_law() const;

 protected:
  // What the partner side prepares once per evaluation (search trees, tool position).
  struct Prepared {
    virtual ~Prepared() = default;
  };
  // The partner at a slave point: the master face's dofs (null for a tool) and, where
  // rates are wanted, the master's velocity at the foot point and its derivatives along
  // the face (zeta), and its displacement since the previous state (mm).
  struct Partner {
    const FaceDofs* master_dofs = nullptr;
    Index master_face = -1;
    Vec3 velocity = Vec3::Zero();
    Vec3 velocity_d1 = Vec3::Zero(), velocity_d2 = Vec3::Zero();
    Vec3 displacement = Vec3::Zero();
  };
  // Once per evaluation. rates: the model's velocities (or finite-difference rates), or
  // null; previous: the previous state, or null; dt: its time step (quasi-static) or 0.
  virtual std::unique_ptr<Prepared> prepare(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                                            const VecX* rates, const VecX* previous) const = 0;
  // k arrives with the slave part filled (n = n_slave, phi, rho = 0); the partner sets
  // the rest (master functions, gap, normal, derivatives). False: no partner (too far,
  // beyond a free edge).
  virtual bool find_partner(const Prepared& prepared, const Vec3& xs, PointKinematics& k, Partner& partner) const = 0;
  // The engage gap of the viscous layer (mm).
  double engage_gap() const;

 private:
  struct Evaluation;
  // The one loop over the contact points behind add_to, sample, commit and updates.
  void evaluate(const Eigen::Ref<const VecX>& x, const InteractionContext& context, InteractionSums* sums,
                std::vector<ContactPointRecord>* records) const;

  std::string name_;
  ContactSurface slave_;
  ContactOptions options_;
  quadrature::TensorRule<2> rule_;
  std::vector<std::vector<FaceBasisValues>> point_basis_;  // per face: the basis at each point
  std::vector<double> weight_;                             // per point: Gauss weight x reference area
  std::vector<double> lambda_;                             // per point, MPa
  std::vector<Vec3> slip_;                                 // per point, mm
  std::vector<Vec3> elastic_;                              // per point: committed elastic slip e, mm (stick_slip)
  // e before the last commit and that commit's time: a state of the committed step (its
  // outputs, reactions, sampled after the commit) is evaluated from the e it started with.
  std::vector<Vec3> elastic_before_;
  double committed_time_ = -1e300;
  std::vector<Vec3> shear_;                                // per point at the last commit (dynamic runs), MPa
  bool shear_known_ = false;                               // shear_ holds the last committed state
  double dissipated_ = 0.0;
  int updates_ = 0;
  // Each point's state at the last tangent assembly (once per Newton iteration): its
  // normal status (-1 no partner within the search distance, 0 open (no bearing
  // pressure; the tail's tie alone), 1 in the rounded band, 2 closed) and its viscous
  // layer (0 off, 1 tapering, 2 engaged), to count the points that changed
  // (contact_state_flips()) and, with SF_NEWTON_TRACE=1 or SF_CONTACT_TRACE=1, to say
  // where (surface_contact.cpp).
  mutable std::vector<signed char> flip_status_;
  // Counts the points whose state changed since the last tangent assembly and, tracing,
  // lists where (x, y, z, gap, pressure of each point in `where`); keeps `status`.
  void report_flips(std::vector<signed char>& status, const std::vector<Eigen::Matrix<double, 5, 1>>& where,
                    bool tracing) const;
};

// Contact points whose state changed between two consecutive tangent assemblies of the
// same interaction, summed over every SurfaceContact of the process since it started:
// the normal status (above) and the viscous layer's engagement. A state change is where
// the law's second derivative jumps (the band's ends, the taper's ends) or, at the search
// distance, where the point drops out: Newton's quadratic convergence is lost while points
// keep changing. Thread-safe (an atomic); the benchmark prints it per step.
long contact_state_flips();

}  // namespace sf::forming
