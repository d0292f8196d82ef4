#include "forming/case/build.hpp"

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common/core/error.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/case/checks.hpp"
#include "forming/contact/body_contact.hpp"
#include "forming/contact/tool_contact.hpp"
#include "forming/material/mooney_rivlin.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"
#include "forming/model/ply_grid.hpp"
#include "forming/model/tied_faces.hpp"
#include "forming/solve/tangent_solver.hpp"

namespace sf::forming {
namespace {

// Penalties of the augmented-Lagrangian constraints, relative to the law's own
// volumetric / fibre stiffness: each multiplier update reduces the constraint
// violation by about this factor.
constexpr double kConstraintPenalty = 100.0;

}  // namespace

Model build_model(const FormingCase& spec) {
  Model model;
  for (const CasePly& p : spec.plies) {
    mesh::SurfaceMesh s =
        mesh::make_rectangle_mesh(p.origin, Vec3::UnitX(), Vec3::UnitY(), p.length_x, p.length_y, p.n1, p.n2);
    PlyMesh ply(std::move(s), p.thickness, p.angle_deg, PlyPlacement::kBottom);
    const CaseMaterial& m = spec.materials.at(static_cast<std::size_t>(p.material_index));
    std::shared_ptr<const Material> law;
    ConstraintTerms ct;
    if (m.kind == CaseMaterial::Kind::kNeoHookean) {
      law = std::make_shared<NeoHookean>(m.neo_hookean);
      ct.kappa = kConstraintPenalty * (m.neo_hookean.lambda + 2.0 * m.neo_hookean.mu);
    } else if (m.kind == CaseMaterial::Kind::kMooneyRivlin) {
      law = std::make_shared<MooneyRivlin>(m.mooney_rivlin);
      const MooneyRivlinParams& q = m.mooney_rivlin;
      ct.kappa = kConstraintPenalty * (q.bulk_modulus() + 4.0 * q.shear_modulus() / 3.0);
    } else {
      law = std::make_shared<TransverselyIsotropic>(m.ti, ply.fibre_direction());
      ct.kappa = kConstraintPenalty * (m.ti.lambda + 2.0 * m.ti.mu_T);
      ct.k_fibre = kConstraintPenalty * (2.0 * m.ti.kappa_f + m.ti.lambda + 2.0 * m.ti.mu_T);
    }
    ct.incompressible = m.incompressible;
    ct.inextensible = m.inextensible && m.kind == CaseMaterial::Kind::kTransverselyIsotropic;
    if (!ct.incompressible) ct.kappa = 0.0;
    if (!ct.inextensible) ct.k_fibre = 0.0;
    model.add_ply(std::move(ply), std::move(law), ct);
  }
  return model;
}

RampedLoads build_loads(const FormingCase& spec, const Model& model) {
  RampedLoads out;
  const VecX X = model.reference_positions();
  for (const CaseLoad& cl : spec.loads) {
    LoadSet set;
    switch (cl.kind) {
      case CaseLoad::Kind::kPressure: {
        PressureLoad p;
        for (Index e = 0; e < model.ply(cl.ply_index).n_elements(); ++e)
          p.faces.push_back({cl.ply_index, e, cl.top ? BrickFace::kTop : BrickFace::kBottom});
        p.pressure = cl.value;
        p.follower = cl.follower;
        set.pressures.push_back(std::move(p));
        break;
      }
      case CaseLoad::Kind::kGravity:
        for (std::size_t b = 0; b < spec.plies.size(); ++b) {
          const double rho = spec.materials.at(static_cast<std::size_t>(spec.plies[b].material_index)).density;
          set.body_forces.push_back({static_cast<int>(b), rho * cl.vector});
        }
        break;
      case CaseLoad::Kind::kEdgeForce: {
        const CasePly& ply = spec.plies.at(static_cast<std::size_t>(cl.ply_index));
        TractionLoad t;
        t.faces = PlyGrid{ply.n1, ply.n2}.side_faces(cl.ply_index, cl.side);  // an edge: the reader rejects bottom
        t.traction = cl.vector / face_area(model, t.faces, X);
        set.tractions.push_back(std::move(t));
        break;
      }
      case CaseLoad::Kind::kPointForce: {
        const CasePly& ply = spec.plies.at(static_cast<std::size_t>(cl.ply_index));
        const Index s = PlyGrid{ply.n1, ply.n2}.surface_node(cl.node_i, cl.node_j);
        for (int layer = 0; layer < 2; ++layer) {
          if (cl.layer >= 0 && cl.layer != layer) continue;
          const double share = cl.layer < 0 ? 0.5 : 1.0;
          const Index node = model.ply(cl.ply_index).node(s, layer);
          for (int c = 0; c < 3; ++c) set.nodal.push_back({model.dof(cl.ply_index, node, 0, c), share * cl.vector[c]});
        }
        break;
      }
    }
    if (cl.table.empty()) {
      out.add(cl.ramp, std::move(set));
      continue;
    }
    // A pressure time table: the set carries p = 1 MPa, scaled by p(t) at t = lambda T.
    const double duration = spec.solver.dynamic ? spec.solver.end_time : spec.solver.process_time;
    LoadTable table;
    for (const auto& [t, p] : cl.table) {
      table.lambda.push_back(t / duration);
      table.factor.push_back(p);
    }
    set.pressures.back().pressure = 1.0;
    out.add(std::move(table), std::move(set));
  }
  return out;
}

Prescriptions build_prescriptions(const FormingCase& spec, const Model& model) {
  std::vector<CaseProblem> conflicts;
  const std::vector<PlyConditions> plies = discretise_boundary_conditions(spec, conflicts);
  if (!conflicts.empty())
    throw InputError(
        located_message(spec.file, conflicts[0].place.line, conflicts[0].place.column, conflicts[0].message));
  Prescriptions out;
  for (int b = 0; b < model.n_bodies(); ++b) out.add(model, b, plies[static_cast<std::size_t>(b)].parameters);
  return out;
}

void add_contacts(const FormingCase& spec, Model& model) {
  for (const CaseContact& c : spec.contacts) {
    ContactOptions o;
    o.normal = c.law.normal;
    o.friction = c.law.friction;
    o.points = c.law.points;
    o.band = c.law.band;
    if (c.tie) {
      model.add_interaction(std::make_shared<TiedFaces>(c.label, model, c.ply, c.top, c.with, c.with_top,
                                                        c.law.normal.stiffness, c.law.points));
      continue;
    }
    ContactSurface slave = ContactSurface::whole_face(model, c.ply, c.top);
    if (c.tool >= 0) {
      model.add_interaction(std::make_shared<ToolContact>(c.label, model, std::move(slave),
                                                          spec.tools.at(static_cast<std::size_t>(c.tool)).tool, o));
    } else if (c.law.two_pass) {
      // Two half-passes: each side's points against the other, forces on its own side.
      o.half_pass = true;
      model.add_interaction(std::make_shared<BodyContact>(c.label, model, std::move(slave),
                                                          ContactSurface::whole_face(model, c.with, c.with_top), o));
      model.add_interaction(std::make_shared<BodyContact>(c.label + " (second pass)", model,
                                                          ContactSurface::whole_face(model, c.with, c.with_top),
                                                          ContactSurface::whole_face(model, c.ply, c.top), o));
    } else {
      model.add_interaction(std::make_shared<BodyContact>(c.label, model, std::move(slave),
                                                          ContactSurface::whole_face(model, c.with, c.with_top), o));
    }
  }
}

Problem build_problem(const FormingCase& spec) {
  Problem problem{build_model(spec), {}, {}, {}};
  problem.loads = build_loads(spec, problem.model);
  problem.prescriptions = build_prescriptions(spec, problem.model);
  for (const CasePly& p : spec.plies)
    problem.density.push_back(spec.materials.at(static_cast<std::size_t>(p.material_index)).density);
  add_contacts(spec, problem.model);
  return problem;
}

StepperSettings stepper_settings(const FormingCase& spec) {
  const CaseSolver& s = spec.solver;
  StepperSettings out;
  out.control = s.arc_length > 0.0 ? Control::kArcLength : s.dynamic ? Control::kDynamic : Control::kLoad;
  out.steps = s.steps;

  out.statics.max_iterations = s.max_iterations;
  out.statics.residual_tol_rel = s.tolerance;
  out.statics.line_search = s.line_search;
  out.statics.min_increment = s.min_increment;
  out.statics.extrapolate = s.extrapolate;
  out.statics.validate();
  // The run's tangent workspaces, made here to carry the linear-solver choice.
  const LinearMode linear = parse_linear_mode(s.linear, "solver linear");
  out.statics.workspace = std::make_shared<TangentWorkspace>();
  out.statics.workspace->linear = linear;
  out.dynamics.workspace = std::make_shared<TangentWorkspace>();
  out.dynamics.workspace->linear = linear;
  out.uzawa.tolerance = s.constraint_tolerance;
  out.process_time = s.process_time;
  out.stabilise.fraction = s.stabilise_fraction;
  out.stabilise.damping = s.stabilise_damping;
  out.stabilise.warn_ratio = s.stabilise_warn_ratio;
  out.stabilise.validate();
  out.branch_switch.amplitude = s.branch_switch_amplitude;
  out.branch_switch.give_up_after = s.branch_switch_give_up_after;
  out.branch_switch.retries = s.branch_switch_retries;
  out.branch_switch.last_retry_damping = s.branch_switch_last_retry_damping;
  out.branch_switch.validate();

  if (s.dynamic) {
    DynamicOptions& d = out.dynamics;
    d.integrator = parse_integrator(s.integrator, "solver integrator");
    d.rho_inf = s.rho_inf;
    d.initial_dt = s.time_step > 0.0 ? s.time_step : s.end_time / (10.0 * s.steps);
    d.max_dt = d.initial_dt;
    d.min_dt = d.initial_dt * s.min_increment * 1e-2;
    d.max_iterations = s.max_iterations;
    d.residual_tol_rel = s.tolerance;
    d.line_search = s.line_search;
    d.keep_step_records = false;  // the run reads the counts and the last residual only
    out.end_time = s.end_time;
  }

  if (s.arc_length > 0.0) {
    ArcLengthOptions& a = out.arc;
    a.arc_length = s.arc_length;
    a.max_arc = 10.0 * s.arc_length;
    a.min_arc = s.arc_length * s.min_increment;
    a.max_steps = s.steps;
    a.max_attempts = 4 * s.steps;
    a.max_iterations = s.max_iterations;
    a.residual_tol_rel = s.tolerance;
    a.max_load_factor = 1.0;
    out.stop_displacement = s.stop_displacement;
  }
  return out;
}

}  // namespace sf::forming
