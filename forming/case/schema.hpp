#pragma once
// What a case file of `simform` holds (YAML; the format is documented in
// docs/forming.md): the data as read and checked by forming/case/reader.hpp, with the
// place in the file of everything a problem may be reported at.
//
//   units: "mm, N, MPa"            # informational; any consistent set works
//   materials:
//     gfpp:
//       transversely_isotropic: {E_f: 25000, E_T: 1, G_L: 0.5, G_T: 0.4}
//       density: 1.5e-9                           # t/mm^3: gravity and dynamics
//       inextensible: true                        # exact element-mean constraints
//   plies:
//     - {name: ply, size: [100, 20], thickness: 2, elements: [10, 2], angle: 0, material: gfpp}
//   boundary_conditions:
//     - clamp: {ply: ply, edge: x0}
//     - displacement: {ply: ply, edge: x1, value: [5, ~, ~], ramp: linear}
//     - symmetry: {ply: ply, plane: bottom}
//   loads:
//     - pressure: {ply: ply, face: top, value: 0.01, follower: true, ramp: linear}
//     - gravity: {acceleration: [0, 0, -9810]}
//   solver: {steps: 10, analysis: static, control: load, tolerance: 1e-8}
//   output: {every: 1, samples: [4, 2]}
//
// A case can ask for: plies of neo-Hookean or transversely isotropic material (the
// compressible forms, optionally with exact element-mean incompressibility and fibre
// inextensibility), clamps, prescribed edge displacements and symmetry planes;
// follower or dead pressure, gravity, edge and point forces, each with its ramp;
// quasi-static load control, arc-length control (through limit points) or implicit
// dynamics with inertia; laminates of separate plies from a layup, rigid tools moving
// by prescribed time functions, and contact (penalty or augmented Lagrangian, viscous
// and Coulomb friction) between plies and between plies and tools:
//
//   laminates:
//     - {name: lam, size: [100, 100], elements: [10, 10], layup: "[0,90]s",
//        ply_thickness: 0.5, material: gfpp, interface: {stiffness: 1000, viscous: 0.02}}
//   tools:
//     - {name: punch, sphere: {centre: [50, 50, 27], radius: 25},
//        motion: {displacement: [0, 0, -10], ramp: linear}}
//   contact:
//     - {ply: lam.4, face: top, tool: punch, stiffness: 1000}
//     - {ply: a, face: top, with: b, with_face: bottom, stiffness: 1000, viscous: 0.02}
//
// Units: those of the file (the samples use mm, N, MPa, s, t/mm^3).

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/core/types.hpp"
#include "forming/contact/contact_law.hpp"
#include "forming/contact/rigid_tool.hpp"
#include "forming/material/mooney_rivlin.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/ply_grid.hpp"
#include "forming/model/prescriptions.hpp"
#include "forming/model/ramp.hpp"

namespace sf::forming {

// 1-based line and column in the case file; 0 = not known.
struct SourcePlace {
  int line = 0;
  int column = 0;
};

struct CaseMaterial {
  enum class Kind { kNeoHookean, kTransverselyIsotropic, kMooneyRivlin };
  std::string name;
  Kind kind = Kind::kNeoHookean;
  NeoHookeanParams neo_hookean;      // kNeoHookean
  MooneyRivlinParams mooney_rivlin;  // kMooneyRivlin
  TransverselyIsotropicParams ti;    // kTransverselyIsotropic (compressible)
  std::string given_as;              // "E, nu", "mu, lambda", "mu_T, mu_L, kappa_f, lambda", "E_f, E_T, G_L, G_T",
                                     // "c10, c01, nu", "c10, c01, kappa"
  double density = 0.0;              // t/mm^3 (0 = not given; gravity and dynamics need it)
  bool incompressible = false;       // element-mean J = 1, exact (augmented Lagrangian)
  bool inextensible = false;         // element-mean I4 = 1 (transversely isotropic only)
  SourcePlace place;
};

struct CasePly {
  std::string name;
  Vec3 origin = Vec3::Zero();  // corner (x0, y0, bottom), mm
  double length_x = 0.0;       // mm
  double length_y = 0.0;       // mm
  double thickness = 0.0;      // mm
  int n1 = 0, n2 = 0;          // elements along x and y
  double angle_deg = 0.0;      // layup angle from x towards y, degrees
  // Plane strain across the width (y): u_y = 0 and d/ds2, d2/ds1ds2 of x and z held at
  // 0 at every node, so with loads and conditions uniform in y the ply is a 2-D strip
  // (forming/case/checks.cpp; use elements [n, 1]).
  bool plane_strain = false;
  std::string material;
  int material_index = -1;
  SourcePlace place;
};

struct CaseBoundary {
  // kClamp: every dof (values and derivatives, both layers) of the edge nodes fixed;
  // kDisplacement: edge translated by value * ramp(load factor), null components free;
  // kSymmetry: mirror plane through the side (forming/model/prescriptions.hpp).
  using Kind = EdgeCondition::Kind;
  Kind kind = Kind::kClamp;
  std::string ply;
  int ply_index = -1;
  PlySide side = PlySide::kX0;
  std::array<std::optional<double>, 3> value{};  // kDisplacement, mm
  Ramp ramp = Ramp::kLinear;
  SourcePlace place;
};

// A load, scaled by ramp(load factor):
//   pressure     {ply, face: top|bottom, value: MPa (positive pushes into the ply),
//                 follower: true (acts on the current face) | false (dead, reference face)}
//   gravity      {acceleration: [x, y, z] mm/s^2, default [0, 0, -9810]}; every material
//                needs a density
//   edge_force   {ply, edge: x0|x1|y0|y1, force: [x, y, z] N in total, spread uniformly
//                 over the side face (dead)}
//   point_force  {ply, node: [i, j] (grid node, 0..elements), layer: bottom|top|both
//                 (both: half on each), force: [x, y, z] N (dead)}
struct CaseLoad {
  enum class Kind { kPressure, kGravity, kEdgeForce, kPointForce };
  Kind kind = Kind::kPressure;
  std::string ply;
  int ply_index = -1;           // -1 for gravity (all plies)
  bool top = true;              // kPressure face
  double value = 0.0;           // kPressure, MPa
  bool follower = true;         // kPressure
  PlySide side = PlySide::kX1;  // kEdgeForce
  int node_i = 0, node_j = 0;   // kPointForce
  int layer = -1;               // kPointForce: 0 bottom, 1 top, -1 both
  Vec3 vector = Vec3::Zero();   // gravity acceleration (mm/s^2) or force (N)
  Ramp ramp = Ramp::kLinear;
  // kPressure: a time table (t s, p MPa), t from 0 increasing, linear between, the last
  // pressure held; t is the process time (load control) or the time of a dynamic run.
  // Empty: value * ramp.
  std::vector<std::array<double, 2>> table;
  SourcePlace place;
};

struct CaseSolver {
  int steps = 10;           // load steps (load factor k / steps)
  int max_iterations = 25;  // Newton iterations per attempt
  double tolerance = 1e-8;  // residual, relative to the force scale
  bool line_search = true;
  double min_increment = 1e-4;         // smallest sub-increment (fraction of a step) before giving up
  double constraint_tolerance = 1e-8;  // |mean J - 1|, |mean (I4 - 1)/2| after the multiplier updates
  // analysis: dynamic (inertia; forming/solve/dynamic_solver.hpp). The load factor is
  // then t / end_time and the steps are output intervals of end_time / steps.
  bool dynamic = false;
  double end_time = 1.0;                         // s
  double time_step = 0.0;                        // s, first (and largest) time step; 0 = end_time / (10 steps)
  std::string integrator = "generalized-alpha";  // | hht-alpha | newmark
  double rho_inf = 0.8;                          // generalised-alpha high-frequency spectral radius
  // control: arc_length (static only): the load factor is an unknown and each step
  // advances a fixed path length (mm) through limit points
  // (forming/solve/arc_length.hpp); steps is then the maximum number of arc-length
  // steps, the run ends past lambda 1.
  double arc_length = 0.0;         // mm; 0 = load control
  double stop_displacement = 0.0;  // mm, arc length only: also end when max |u| reaches this
  // Load control: the process time of the load factor (t = lambda process_time, s):
  // tools move with it and friction takes its slip rates over it.
  // predictor: extrapolate (load control): each step's first iterate starts from the
  // last step's increment (forming/solve/static_solver.hpp StaticOptions::extrapolate).
  bool extrapolate = false;
  double process_time = 1.0;  // s
  // linear: how the Newton tangent is solved: direct (sparse Cholesky / LDL^T / LU),
  // iterative (GMRES preconditioned by an earlier tangent's factorisation) or auto (direct);
  // forming/solve/tangent_solver.hpp. (iterative-ply: benchmarks only, set directly.)
  std::string linear = "auto";
  // stabilise (load control): viscous stabilisation F_v = c M* v
  // (forming/solve/stabilisation.hpp): {fraction: f} calibrates c from the first step so
  // that it dissipates the fraction f of the strain energy it stores (2e-4 is Abaqus'
  // default), {damping: c} gives c (N s/mm^4); warn_ratio: dissipated / strain energy
  // above which the run warns (default 0.05). Both 0: off (the default).
  double stabilise_fraction = 0.0;
  double stabilise_damping = 0.0;    // N s/mm^4
  double stabilise_warn_ratio = 0.05;
  SourcePlace stabilise_place;  // of the "stabilise" key's value; 0: not given
  // branch_switch (load control): {amplitude: A} moves an unstable converged state (and a
  // failed step's last converged sub-step) by A mm along its tangent's nearest-zero mode
  // (forming/solve/branch_switch.hpp). 0: off (the default). May change for a restart.
  double branch_switch_amplitude = 0.0;  // mm
  // {give_up_after: N, retries: R}: a failed step gives up after N failed sub-steps and
  // is retried from a switched state at most R times (BranchSwitchOptions).
  int branch_switch_give_up_after = 4;
  int branch_switch_retries = 4;
  // {last_retry_damping: F}: the last retry of a failed step runs with F times the run's
  // stabilisation damping (1: not raised, the default; needs solver stabilise).
  double branch_switch_last_retry_damping = 1.0;
  SourcePlace branch_switch_place;       // of the "branch_switch" key's value; 0: not given
  SourcePlace analysis_place;  // of the value of "analysis" (cross-field problems); 0: not given
  SourcePlace control_place;   // of the value of "control"; 0: not given
};

// A laminate: plies of one rectangle and mesh stacked bottom first, each its own body
// named "<name>.<k>" (k = 1 bottom .. n top) in spec.plies, with contact between
// neighbours (top of ply k against the bottom of ply k + 1; in spec.contacts).
struct CaseLaminate {
  std::string name;
  std::string layup;           // as given (a string), or "list" for an explicit list
  std::vector<double> angles;  // degrees, bottom first
  int first_ply = 0;           // index of ply 1 in spec.plies
  SourcePlace place;
};

// The laws of one contact pair (forming/contact/contact_law.hpp).
struct CaseContactLaw {
  NormalLaw normal;       // stiffness S_n (N/mm^3), augmented + tolerance (mm)
  FrictionLaw friction;   // viscous c_f (N s/mm^3), coulomb mu, stick_velocity (mm/s), engage_gap (mm)
  int points = 6;         // contact points per face direction
  bool two_pass = false;  // ply-ply: two half-passes (forming/contact/surface_contact.hpp)
  double band = 0.0;      // mm, rounded kink of the normal law; 0: default (1e-3 ply thicknesses)
};

struct CaseTool {
  std::string name;
  RigidTool tool;    // shape at rest and motion
  std::string file;  // mesh tools: the STL as resolved (relative to the case file)
  SourcePlace place;
};

// A contact pair: the `face` of ply `ply` (slave: its contact points) against a tool or
// against the `with_face` of ply `with`.
struct CaseContact {
  int ply = -1;
  bool top = true;
  int tool = -1;  // index into spec.tools, or -1
  int with = -1;  // index into spec.plies, or -1
  bool with_top = false;
  CaseContactLaw law;
  // Ply-ply: the faces tied (forming/model/tied_faces.hpp, penalty law.normal.stiffness
  // with law.points per face direction) instead of in contact: the vacuum's grip of
  // `diaphragms: {vacuum: {hold: tie}}`.
  bool tie = false;
  std::string label;  // "lam.1/lam.2", "lam.4/punch"
  SourcePlace place;
};

// A double-diaphragm set-up (forming/case/diaphragm_reader.hpp): two isotropic sheets
// "<name>.lower" and "<name>.upper" in spec.plies around laminate `laminate`, clamped in
// a frame; their loads, conditions and contact pairs are in spec.loads, spec.boundaries
// and spec.contacts like any other.
struct CaseDiaphragms {
  std::string name;
  std::string laminate;
  int lower = -1;  // index into spec.plies
  int upper = -1;
  SourcePlace place;
};

struct CaseOutput {
  int every = 1;              // write a .vtu every N steps (and always the last)
  int samples_inplane = 4;    // hexahedra per element per in-plane direction in the .vtu
  int samples_thickness = 2;  // ... through the thickness
};

struct FormingCase {
  std::string file;  // as given (messages)
  std::string units = "mm, N, MPa";
  std::vector<CaseMaterial> materials;
  std::vector<CasePly> plies;
  std::vector<CaseBoundary> boundaries;
  std::vector<CaseLoad> loads;
  std::vector<CaseLaminate> laminates;
  std::vector<CaseTool> tools;
  std::vector<CaseContact> contacts;
  std::vector<CaseDiaphragms> diaphragms;
  CaseSolver solver;
  CaseOutput output;
  // Every value of the case file except `output`, flattened ("materials.carbon.E_T",
  // "1000"), and a checksum of each file it names (tool STLs): what a restart must match
  // (forming/output/restart.hpp). Filled by the reader; empty for a case built in code.
  std::vector<std::pair<std::string, std::string>> fingerprint;

  int find_ply(const std::string& name) const;  // -1 when absent
};

// True for a flattened case key a --restart may change (FormingCase::fingerprint leaves
// them out, and a restart file written before they were left out is compared without
// them): the solver keys that steer how a step is solved, not what is solved -
// solver.max_iterations, tolerance, min_increment, line_search, predictor, linear,
// branch_switch (and its fields) and stabilise.warn_ratio.
bool restart_may_change(const std::string& key);

}  // namespace sf::forming
