#pragma once
// The model the solvers work on: bodies (plies of ply bricks, each with its material and
// optional exact constraints) and the interactions between them, assembled into one
// internal force and tangent.
//
// Bodies and unknowns
//   Body b is a PlyMesh with its Material (forming/model/ply_mesh.hpp,
//   forming/material/material.hpp). Global dofs are the bodies' dofs one body after the
//   other: body b owns [offset(b), offset(b) + ply(b).n_dofs()), inside it the ply's own
//   numbering dof = 3 (4 node + d) + coord. Unknowns are current POSITIONS x (not
//   displacements), flattened like PlyMesh::flatten; a solve typically starts from
//   reference_positions().
//
//         body 0 dofs          body 1 dofs               ...
//   x = [ 0 .. n_0 - 1 | n_0 .. n_0 + n_1 - 1 | ... ]    (n_b = ply(b).n_dofs())
//
// Assembly
//   energy  Pi(x) = sum over bricks of the element energy (forming/element/element.hpp,
//           constraint terms included) + the energy of every interaction,
//   force   f(x) = dPi/dx + dissipative interaction forces: the resisting force, N,
//   tangent K = df/dx, N/mm; damping D = df/dv, N s/mm (velocity-dependent interactions),
// element vectors mapped to global dofs through the element maps (arc-length scale
// factors applied). The residual a solver drives to zero is r = f(x) - f_ext.
//
// Interactions (forming/model/interaction.hpp) are owned by the model (shared, like the
// materials) and summed into every assembly, so the static, dynamic and arc-length
// solvers see contact, tools and springs without knowing they are there.
//
// Units: positions mm, forces N, energies N mm, stiffness N/mm (any consistent set).

#include <memory>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/linalg/pattern_assembler.hpp"
#include "common/linalg/sparse.hpp"
#include "forming/element/element.hpp"
#include "forming/material/material.hpp"
#include "forming/model/interaction.hpp"
#include "forming/model/ply_mesh.hpp"

namespace sf::forming {

// Result of assembling the model at a state.
struct Assembly {
  bool ok = true;              // false: an element or interaction found the state inadmissible (see message)
  std::string message;         // empty when ok
  double energy = 0.0;         // stored energy: elements + interactions, N mm
  double strain_energy = 0.0;  // the elements' part, N mm
  VecX force;                  // f, n_dofs, N
  // |f| of the elements alone, N: the force scale of a state where interactions (contact)
  // balance the elements without external loads, so |f| itself is only the residual.
  double element_force_norm = 0.0;
  linalg::SparseMatrix tangent;  // K = df/dx, n_dofs x n_dofs, N/mm (empty unless asked for)
  linalg::SparseMatrix damping;  // D = df/dv, N s/mm (empty unless asked for and some interaction depends on v)
  VecX tangent_times;            // K d for the direction d of assemble_into (n_dofs, N), else empty
};

class Model {
 public:
  explicit Model(ElementRule rule = {});

  // Adds a ply; returns its body index. The material is shared (several plies may use
  // one law); for the TI law its fibre direction should be ply.fibre_direction().
  // `constraints`: element-mean incompressibility / fibre inextensibility of this ply
  // (forming/element/element.hpp ConstraintTerms: the flags and the penalties kappa,
  // k_fibre; its p and T are the starting multipliers of every element).
  int add_ply(PlyMesh ply, std::shared_ptr<const Material> material, const ConstraintTerms& constraints = {});

  // Adds an interaction between bodies (or between a body and a tool); returns its index.
  // Throws sf::InputError for a null pointer.
  int add_interaction(std::shared_ptr<Interaction> interaction);
  int n_interactions() const { return static_cast<int>(interactions_.size()); }
  const Interaction& interaction(int i) const { return *interactions_[static_cast<std::size_t>(i)]; }
  // Non-const: the steppers commit state and update multipliers (interaction.hpp).
  Interaction& interaction(int i) { return *interactions_[static_cast<std::size_t>(i)]; }
  // False when some interaction's tangent is unsymmetric (solvers then factorise with LU).
  bool symmetric_tangent() const;

  // Element multipliers (pressure p and fibre tension T, MPa) of a constrained body.
  bool constrained(int body) const { return bodies_[body].constraints.active(); }
  bool any_constrained() const;
  const ConstraintTerms& constraints(int body) const { return bodies_[body].constraints; }
  const std::vector<double>& pressures(int body) const { return bodies_[body].p; }
  const std::vector<double>& tensions(int body) const { return bodies_[body].T; }
  void set_multipliers(int body, std::vector<double> p, std::vector<double> T);

  // Per element of `body` at positions x: mean constraint values and the effective
  // multipliers p_eff = p - kappa g_J, T_eff = T + k_fibre g_T (the Uzawa update).
  struct ConstraintState {
    double g_J = 0.0, g_T = 0.0, p_eff = 0.0, T_eff = 0.0, volume = 0.0;
  };
  std::vector<ConstraintState> constraint_state(int body, const Eigen::Ref<const VecX>& x) const;

  int n_bodies() const { return static_cast<int>(bodies_.size()); }
  Index n_dofs() const { return n_dofs_; }
  const PlyMesh& ply(int body) const { return bodies_[body].ply; }
  const Material& material(int body) const { return *bodies_[body].material; }
  Index offset(int body) const { return bodies_[body].offset; }
  // Global dof of (body, ply node, parameter d, coordinate).
  Index dof(int body, Index node, int d, int coord) const { return offset(body) + PlyMesh::dof(node, d, coord); }
  const ElementRule& rule() const { return rule_; }

  // Global dofs of brick e of `body`, expanded per (function, map term, coordinate):
  // element-vector entry local[a] (= 3 k + i) contributes coefs[a] times to global dof
  // dofs[a]; repeated dofs (collapsed elements) are summed by the caller.
  struct ElementDofs {
    std::vector<Index> dofs;
    std::vector<double> coefs;
    std::vector<int> local;
  };
  ElementDofs element_dofs(int body, Index e) const;

  // Reference positions of all bodies (n_dofs, mm).
  VecX reference_positions() const;
  // Dofs no element uses (e.g. the cross parameter of a collapsed apex): the solver fixes them.
  std::vector<bool> used_dofs() const;

  // Energy, force and (when want_tangent) tangent at positions x (n_dofs), time 0 and no
  // velocities: what a quasi-static solve sees.
  Assembly assemble(const Eigen::Ref<const VecX>& x, bool want_tangent) const;
  // The same with the time and (dynamic runs) velocities the interactions may depend on;
  // want_tangent also asks for the damping matrix when velocities are given.
  Assembly assemble(const Eigen::Ref<const VecX>& x, const InteractionContext& context, bool want_tangent) const;

  // Assembly for a Newton solver (the fast path): energy and force as above; with
  // `tangent`, K restricted to that assembler's active dofs written into its fixed
  // pattern (set to zero first; interaction entries merged, the pattern growing only
  // when one falls outside it); with `direction` (n_dofs), also K direction over ALL
  // dofs in tangent_times (e.g. K_fp dx_p for a predictor). Elements are evaluated on
  // threads() threads, colour by colour, so the result is the same bit for bit for any
  // thread count. The damping matrix (velocity-dependent interactions, velocities
  // given, tangent asked for) comes back in `damping` as with assemble().
  Assembly assemble_into(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                         linalg::PatternAssembler* tangent, const VecX* direction = nullptr) const;
  // The pattern for assemble_into: the unknowns `active` (n_dofs flags), the lower
  // triangle when `symmetric` (else both).
  linalg::PatternAssembler make_pattern(const std::vector<bool>& active, bool symmetric) const;
  // The element entries (global dof, coefficient, local index) of every brick of every
  // body, bodies in order: what make_pattern lays out.
  const std::vector<linalg::ElementEntries>& element_entries() const { return entries_; }
  // Threads for the element loop: 0 (default) = sf::default_threads() (SF_THREADS, else
  // OMP_NUM_THREADS, else the cores; common/core/parallel.hpp); results do not depend on it.
  void set_threads(int threads) { threads_ = threads; }
  int threads() const;
  // Whether a growing tangent pattern is laid out for every interaction pair within the
  // search band (merge_interactions; default on). Process-wide: for benchmarks comparing
  // re-analyses with and without it (bench/simform_dome_bench.cpp --no-band-pattern).
  static void set_band_pattern(bool on);
  static bool band_pattern();
  // The brick kernel the assembly uses (its flop counts, for benchmarks).
  const BrickKernel& kernel() const { return kernel_; }
  // The straightforward assembly (triplets, full n_dofs x n_dofs tangent) that
  // assemble() replaced; kept as the reference the tests compare the fast path with.
  Assembly assemble_reference(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                              bool want_tangent) const;

  // Deformation gradient at every Gauss point of every brick of `body` (element-major,
  // points in ElementRule::brick() order), for checks and outputs.
  std::vector<Mat3> deformation_gradients(int body, const Eigen::Ref<const VecX>& x) const;

 private:
  struct Body {
    PlyMesh ply;
    std::shared_ptr<const Material> material;
    Index offset = 0;
    ConstraintTerms constraints;  // flags and penalties
    std::vector<double> p, T;     // per element multipliers (when constrained)
  };
  ConstraintTerms element_constraints(const Body& b, Index e) const;
  // Adds the interactions' sums to `out` (elements done); false when one rejects the state.
  // With `pattern`, interactions may add their stiffness straight into it.
  bool add_interactions(const Eigen::Ref<const VecX>& x, const InteractionContext& context, bool want_tangent,
                        linalg::TripletAssembler& stiffness, Assembly& out,
                        linalg::PatternAssembler* pattern = nullptr) const;
  // Interactions' stiffness (and direction product) into the fast assembly.
  // When the pattern must grow it grows for every interaction's pattern_blocks at x as
  // well (contact: every pair within the search band), so pairs closing later inside the
  // band need no new growth.
  void merge_interactions(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                          const linalg::TripletAssembler& stiffness, linalg::PatternAssembler* tangent,
                          const VecX* direction, Assembly& out) const;
  ElementRule rule_;
  quadrature::TensorRule<3> brick_rule_;
  BrickKernel kernel_;
  std::vector<Body> bodies_;
  // Per brick of every body (bodies in order): body, element, entries, reference
  // parameters; and the colouring of the bricks for the threaded loop.
  std::vector<std::pair<int, Index>> bricks_;
  std::vector<linalg::ElementEntries> entries_;
  std::vector<BrickParams> reference_params_;
  std::vector<std::vector<Index>> colours_;
  int threads_ = 0;
  std::vector<std::shared_ptr<Interaction>> interactions_;
  Index n_dofs_ = 0;
};

// The displacement of largest magnitude over the value parameters of every node of
// every body, x - X (mm); zero for an empty model.
Vec3 largest_displacement(const Model& model, const Eigen::Ref<const VecX>& x, const Eigen::Ref<const VecX>& X);

}  // namespace sf::forming
