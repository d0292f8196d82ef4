#include "forming/run/run.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "common/basis/hermite.hpp"
#include "common/cli/progress.hpp"
#include "common/core/error.hpp"
#include "common/io/atomic_file.hpp"
#include "common/io/csv.hpp"
#include "common/io/json.hpp"
#include "common/io/vtk_xml.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/solve/arc_length.hpp"
#include "forming/solve/dynamic_solver.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/material/transversely_isotropic.hpp"

namespace sf::forming {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// Penalties of the augmented-Lagrangian constraints, relative to the law's own
// volumetric / fibre stiffness: each multiplier update reduces the constraint
// violation by about this factor.
constexpr double kConstraintPenalty = 100.0;

// A prescribed dof with its reference value and load-factor dependence.
struct Prescription {
  Index dof = 0;
  double reference = 0.0;
  double displacement = 0.0;
  Ramp ramp = Ramp::kLinear;
};

std::vector<Prescription> prescriptions(const FormingCase& spec, const Model& model) {
  const VecX X = model.reference_positions();
  std::vector<Prescription> out;
  std::vector<CaseProblem> conflicts;
  for (int b = 0; b < model.n_bodies(); ++b)
    for (const PlyPrescription& p : ply_prescriptions(spec, b, conflicts)) {
      const Index dof = model.dof(b, p.node, p.d, p.coord);
      out.push_back({dof, X[dof], p.displacement, p.ramp});
    }
  if (!conflicts.empty())
    throw InputError(located_message(spec.file, conflicts[0].place.line, conflicts[0].place.column,
                                     conflicts[0].message));
  return out;
}

std::vector<PrescribedDof> targets(const std::vector<Prescription>& ps, double lambda) {
  std::vector<PrescribedDof> out;
  out.reserve(ps.size());
  for (const Prescription& p : ps) out.push_back({p.dof, p.reference + p.displacement * ramp_value(p.ramp, lambda)});
  return out;
}

// The edge whose displacement and reaction go into history.csv: the first displacement
// condition (or, without one, the first condition).
struct Tool {
  std::string label;
  std::vector<Index> value_dofs_x;  // global dof of coordinate 0 of each value parameter
};

Tool find_tool(const FormingCase& spec, const Model& model) {
  Tool t;
  const CaseBoundary* chosen = nullptr;
  for (const CaseBoundary& bc : spec.boundaries)
    if (bc.kind == CaseBoundary::Kind::kDisplacement) {
      chosen = &bc;
      break;
    }
  if (!chosen && !spec.boundaries.empty()) chosen = &spec.boundaries.front();
  if (!chosen) return t;
  const CasePly& p = spec.plies[static_cast<std::size_t>(chosen->ply_index)];
  const Index n_s = static_cast<Index>(p.n1 + 1) * (p.n2 + 1);
  t.label = to_string(chosen->kind) + " on " + to_string(chosen->side) + " of ply '" + p.name + "'";
  for (const Index s : side_surface_nodes(p.n1, p.n2, chosen->side))
    for (int layer = 0; layer < 2; ++layer)
      t.value_dofs_x.push_back(model.dof(chosen->ply_index, s + layer * n_s, 0, 0));
  return t;
}

struct ToolState {
  Vec3 displacement = Vec3::Zero();
  Vec3 force = Vec3::Zero();
};

ToolState tool_state(const Tool& tool, const VecX& x, const VecX& X, const VecX& reactions) {
  ToolState s;
  if (tool.value_dofs_x.empty()) return s;
  for (const Index d : tool.value_dofs_x)
    for (int c = 0; c < 3; ++c) {
      s.displacement[c] += x[d + c] - X[d + c];
      if (reactions.size() > 0) s.force[c] += reactions[d + c];
    }
  s.displacement /= static_cast<double>(tool.value_dofs_x.size());
  return s;
}

// Position and deformation gradient of brick e of a body at xi.
struct PointState {
  Vec3 X, x;
  Mat3 F;
};

PointState evaluate_point(const BrickParams& Xe, const BrickParams& xe, const Vec3& xi) {
  const basis::BrickValues v = basis::BicubicHermiteLinear::evaluate(xi, basis::kValues | basis::kFirst);
  PointState s;
  s.X = Xe.transpose() * v.value;
  s.x = xe.transpose() * v.value;
  const Mat3 G = Xe.transpose() * v.first;
  const Mat3 g = xe.transpose() * v.first;
  s.F = g * G.inverse();
  return s;
}

io::VolumeMesh tessellate(const FormingCase& spec, const Model& model, const VecX& x) {
  const int ns = spec.output.samples_inplane, nt = spec.output.samples_thickness;
  io::VolumeMesh mesh;
  std::vector<Vec3> points;
  std::vector<double> disp, stress, fibre, stretch, body_id, pressure, tension;
  bool constrained = false;
  for (int b = 0; b < model.n_bodies(); ++b) constrained = constrained || model.constrained(b);
  for (int b = 0; b < model.n_bodies(); ++b) {
    const PlyMesh& ply = model.ply(b);
    const Material& material = model.material(b);
    // Element pressure and fibre tension of a constrained ply (sigma gains -p I + T/J a a).
    const std::vector<Model::ConstraintState> cs = model.constraint_state(b, x);
    const Vec3 a0 = ply.fibre_direction();
    const MatX xb = PlyMesh::unflatten(x.segment(model.offset(b), ply.n_dofs()));
    for (Index e = 0; e < ply.n_elements(); ++e) {
      const BrickParams Xe = ply.element_parameters(e, ply.reference());
      const BrickParams xe = ply.element_parameters(e, xb);
      const Index first = static_cast<Index>(points.size());
      for (int k = 0; k <= nt; ++k)
        for (int j = 0; j <= ns; ++j)
          for (int i = 0; i <= ns; ++i) {
            const PointState s = evaluate_point(Xe, xe, Vec3(double(i) / ns, double(j) / ns, double(k) / nt));
            points.push_back(s.x);
            for (int c = 0; c < 3; ++c) disp.push_back(s.x[c] - s.X[c]);
          }
      auto pid = [&](int i, int j, int k) { return first + (static_cast<Index>(k) * (ns + 1) + j) * (ns + 1) + i; };
      for (int k = 0; k < nt; ++k)
        for (int j = 0; j < ns; ++j)
          for (int i = 0; i < ns; ++i) {
            mesh.add_cell(io::CellType::kHexahedron,
                          {pid(i, j, k), pid(i + 1, j, k), pid(i + 1, j + 1, k), pid(i, j + 1, k),
                           pid(i, j, k + 1), pid(i + 1, j, k + 1), pid(i + 1, j + 1, k + 1), pid(i, j + 1, k + 1)});
            const Vec3 xi((i + 0.5) / ns, (j + 0.5) / ns, (k + 0.5) / nt);
            const PointState s = evaluate_point(Xe, xe, xi);
            const Mat3 C = s.F.transpose() * s.F;
            Mat3 sigma = Mat3::Constant(std::nan(""));
            if (s.F.determinant() > 0.0) sigma = cauchy_stress(s.F, material.evaluate(C, false).stress);
            const Vec3 a = s.F * a0;
            double p_e = 0.0, t_e = 0.0;
            if (!cs.empty()) {
              const ConstraintTerms& ct = model.constraints(b);
              p_e = ct.incompressible ? cs[static_cast<std::size_t>(e)].p_eff : 0.0;
              t_e = ct.inextensible ? cs[static_cast<std::size_t>(e)].T_eff : 0.0;
              sigma += -p_e * Mat3::Identity() + (t_e / s.F.determinant()) * a * a.transpose();
            }
            if (constrained) {
              pressure.push_back(p_e);
              tension.push_back(t_e);
            }
            const Vec6 v = voigt_stress(sigma);
            for (int c = 0; c < 6; ++c) stress.push_back(v[c]);
            const double lam = a.norm();
            for (int c = 0; c < 3; ++c) fibre.push_back(lam > 0.0 ? a[c] / lam : 0.0);
            stretch.push_back(lam);
            body_id.push_back(b);
          }
    }
  }
  mesh.points.resize(static_cast<Index>(points.size()), 3);
  for (std::size_t p = 0; p < points.size(); ++p) mesh.points.row(static_cast<Index>(p)) = points[p].transpose();
  mesh.point_data.push_back({"displacement", 3, std::move(disp)});
  mesh.cell_data.push_back({"cauchy_stress", 6, std::move(stress)});
  mesh.cell_data.push_back({"fibre_direction", 3, std::move(fibre)});
  mesh.cell_data.push_back({"fibre_stretch", 1, std::move(stretch)});
  mesh.cell_data.push_back({"ply", 1, std::move(body_id)});
  if (constrained) {
    mesh.cell_data.push_back({"pressure", 1, std::move(pressure)});
    mesh.cell_data.push_back({"fibre_tension", 1, std::move(tension)});
  }
  return mesh;
}

// n x n marks on the top face of body b, reference and deformed.
void write_grid(const std::string& path, const FormingCase& spec, const Model& model, int b, const VecX& x, int n) {
  const CasePly& p = spec.plies[static_cast<std::size_t>(b)];
  const PlyMesh& ply = model.ply(b);
  const MatX xb = PlyMesh::unflatten(x.segment(model.offset(b), ply.n_dofs()));
  io::write_file_atomic(path, [&](std::ostream& out) {
    out << "# simform --grid-out: " << n << " x " << n << " marks on the top face of ply '" << p.name
        << "' (case " << spec.file << "), mm\n";
    io::CsvWriter w(out, {"id", "X", "Y", "Z", "x", "y", "z", "i", "j"});
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double u = double(i) / (n - 1) * p.n1, v = double(j) / (n - 1) * p.n2;
        const int ie = std::min(static_cast<int>(u), p.n1 - 1), je = std::min(static_cast<int>(v), p.n2 - 1);
        const Index e = static_cast<Index>(je) * p.n1 + ie;
        const PointState s = evaluate_point(ply.element_parameters(e, ply.reference()), ply.element_parameters(e, xb),
                                            Vec3(u - ie, v - je, 1.0));
        w.begin_row().add("m" + std::to_string(i) + "_" + std::to_string(j));
        for (int c = 0; c < 3; ++c) w.add(s.X[c]);
        for (int c = 0; c < 3; ++c) w.add(s.x[c]);
        w.add(i).add(j).end_row();
      }
  });
}

nlohmann::json parameters_json(const FormingCase& spec, const Model& model) {
  nlohmann::json j;
  j["units"] = spec.units;
  for (const CaseMaterial& m : spec.materials) {
    nlohmann::json mj{{"name", m.name}, {"given_as", m.given_as}};
    if (m.kind == CaseMaterial::Kind::kNeoHookean) {
      mj["law"] = "neo_hookean";
      mj["mu"] = m.neo_hookean.mu;
      mj["lambda"] = m.neo_hookean.lambda;
    } else {
      const TransverselyIsotropicModuli mod = small_strain_moduli(m.ti);
      mj["law"] = "transversely_isotropic (compressible)";
      mj["mu_T"] = m.ti.mu_T;
      mj["mu_L"] = m.ti.mu_L;
      mj["kappa_f"] = m.ti.kappa_f;
      mj["lambda"] = m.ti.lambda;
      mj["small_strain"] = {{"E_L", mod.E_L}, {"E_T", mod.E_T}, {"G_L", mod.G_L},
                            {"G_T", mod.G_T}, {"nu_LT", mod.nu_LT}, {"nu_TT", mod.nu_TT}};
    }
    j["materials"].push_back(mj);
  }
  for (std::size_t b = 0; b < spec.plies.size(); ++b) {
    const CasePly& p = spec.plies[b];
    const Vec3 a0 = model.ply(static_cast<int>(b)).fibre_direction();
    j["plies"].push_back({{"name", p.name},
                          {"origin", {p.origin.x(), p.origin.y(), p.origin.z()}},
                          {"size", {p.length_x, p.length_y}},
                          {"thickness", p.thickness},
                          {"elements", {p.n1, p.n2}},
                          {"angle", p.angle_deg},
                          {"fibre_direction", {a0.x(), a0.y(), a0.z()}},
                          {"material", p.material}});
  }
  for (const CaseBoundary& bc : spec.boundaries) {
    nlohmann::json bj{{"kind", to_string(bc.kind)}, {"ply", bc.ply}, {"side", to_string(bc.side)}};
    if (bc.kind == CaseBoundary::Kind::kDisplacement) {
      for (const auto& v : bc.value) bj["value"].push_back(v ? nlohmann::json(*v) : nlohmann::json());
      bj["ramp"] = to_string(bc.ramp);
    }
    j["boundary_conditions"].push_back(bj);
  }
  j["solver"] = {{"steps", spec.solver.steps},
                 {"max_iterations", spec.solver.max_iterations},
                 {"tolerance", spec.solver.tolerance},
                 {"line_search", spec.solver.line_search},
                 {"min_increment", spec.solver.min_increment}};
  j["output"] = {{"every", spec.output.every},
                 {"samples", {spec.output.samples_inplane, spec.output.samples_thickness}}};
  j["model"] = {{"dofs", model.n_dofs()},
                {"element", "ply brick: bicubic Hermite in-plane x linear through the thickness"},
                {"quadrature", {model.rule().n_inplane, model.rule().n_inplane, model.rule().n_thickness}}};
  return j;
}

std::string step_name(int k) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "steps/step_%04d.vtu", k);
  return buf;
}

}  // namespace

void RunOptions::validate() const {
  if (out_dir.empty()) throw UsageError("--out: an output folder is required");
  if (grid_marks < 2) throw UsageError("--grid-marks: expected at least 2, found " + std::to_string(grid_marks));
}

std::string RunReport::brief() const {
  std::ostringstream os;
  if (status == Status::kStopped)
    os << message;
  else if (ok())
    os << "converged: " << steps_converged << " steps, " << total_iterations << " Newton iterations, |r| "
       << sci(final_residual) << " N";
  else
    os << "not converged: " << message;
  return os.str();
}

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

ExternalLoad CaseLoads::at(const Model& model, double lambda, const VecX& x, bool want_tangent) const {
  ExternalLoad out;
  out.force = VecX::Zero(model.n_dofs());
  for (const auto& [ramp, set] : sets) {
    const double factor = ramp_value(ramp, std::clamp(lambda, 0.0, 1.0));
    if (factor == 0.0) continue;
    ExternalLoad l = set.assemble(model, x, factor, want_tangent);
    out.force += l.force;
    if (l.tangent.size() == 0) continue;
    if (out.tangent.size() == 0) out.tangent = std::move(l.tangent);
    else out.tangent += l.tangent;
  }
  return out;
}

CaseLoads build_loads(const FormingCase& spec, const Model& model) {
  CaseLoads out;
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
        auto element = [&](int i, int j) { return static_cast<Index>(j) * ply.n1 + i; };
        switch (cl.side) {
          case PlySide::kX0: for (int j = 0; j < ply.n2; ++j) t.faces.push_back({cl.ply_index, element(0, j), BrickFace::kXi1Min}); break;
          case PlySide::kX1: for (int j = 0; j < ply.n2; ++j) t.faces.push_back({cl.ply_index, element(ply.n1 - 1, j), BrickFace::kXi1Max}); break;
          case PlySide::kY0: for (int i = 0; i < ply.n1; ++i) t.faces.push_back({cl.ply_index, element(i, 0), BrickFace::kXi2Min}); break;
          case PlySide::kY1: for (int i = 0; i < ply.n1; ++i) t.faces.push_back({cl.ply_index, element(i, ply.n2 - 1), BrickFace::kXi2Max}); break;
          case PlySide::kBottom: break;  // not an edge (rejected by the case reader)
        }
        t.traction = cl.vector / face_area(model, t.faces, X);
        set.tractions.push_back(std::move(t));
        break;
      }
      case CaseLoad::Kind::kPointForce: {
        const CasePly& ply = spec.plies.at(static_cast<std::size_t>(cl.ply_index));
        const Index s = static_cast<Index>(cl.node_j) * (ply.n1 + 1) + cl.node_i;
        for (int layer = 0; layer < 2; ++layer) {
          if (cl.layer >= 0 && cl.layer != layer) continue;
          const double share = cl.layer < 0 ? 0.5 : 1.0;
          for (int c = 0; c < 3; ++c)
            set.nodal.push_back({model.dof(cl.ply_index, model.ply(cl.ply_index).node(s, layer), 0, c), share * cl.vector[c]});
        }
        break;
      }
    }
    out.follower = out.follower || set.has_follower();
    out.sets.emplace_back(cl.ramp, std::move(set));
  }
  return out;
}

std::vector<PrescribedDof> prescribed_at(const FormingCase& spec, const Model& model, double lambda) {
  return targets(prescriptions(spec, model), lambda);
}

namespace {

// What a restart file must match: the model's size and the plies' definitions.
std::string model_fingerprint(const FormingCase& spec, const Model& model) {
  std::ostringstream os;
  os.precision(17);
  os << "dofs " << model.n_dofs();
  for (const CasePly& p : spec.plies)
    os << "; ply " << p.name << " " << p.origin.transpose() << " " << p.length_x << " " << p.length_y << " "
       << p.thickness << " " << p.n1 << "x" << p.n2 << " " << p.angle_deg << " " << p.material;
  return os.str();
}

struct RestartState {
  int step = 0;
  double load_factor = 0.0;
  VecX positions;
  VecX velocities;  // dynamic runs (mm/s); empty for static ones
  std::vector<std::vector<double>> p, t;  // per body
  std::string history_rows;
  std::vector<std::pair<double, std::string>> frames;
};

void write_restart(const std::string& path, const FormingCase& spec, const Model& model, const RestartState& s) {
  nlohmann::json j;
  j["format"] = "simform-restart-1";
  j["case"] = spec.file;
  j["fingerprint"] = model_fingerprint(spec, model);
  j["step"] = s.step;
  j["load_factor"] = s.load_factor;
  j["positions"] = std::vector<double>(s.positions.data(), s.positions.data() + s.positions.size());
  j["velocities"] = std::vector<double>(s.velocities.data(), s.velocities.data() + s.velocities.size());
  nlohmann::json m = nlohmann::json::array();
  for (int b = 0; b < model.n_bodies(); ++b) m.push_back({{"p", model.pressures(b)}, {"T", model.tensions(b)}});
  j["multipliers"] = m;
  j["history_rows"] = s.history_rows;
  nlohmann::json f = nlohmann::json::array();
  for (const auto& [lam, name] : s.frames) f.push_back({lam, name});
  j["frames"] = f;
  io::write_file_atomic(path, j.dump());
}

RestartState read_restart(const std::string& path, const FormingCase& spec, Model& model) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": no restart file (a run writes it with every frame; run without --restart first)");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    throw InputError(path + ": not a readable restart file (" + e.what() + ")");
  }
  if (j.value("format", "") != "simform-restart-1") throw InputError(path + ": not a simform restart file");
  if (j.value("fingerprint", "") != model_fingerprint(spec, model))
    throw InputError(path + ": written for a different model (plies, meshes or materials changed since; only solver, "
                            "loads and output settings may change for a restart)");
  RestartState s;
  s.step = j.at("step").get<int>();
  s.load_factor = j.at("load_factor").get<double>();
  const std::vector<double> x = j.at("positions").get<std::vector<double>>();
  s.positions = Eigen::Map<const VecX>(x.data(), static_cast<Index>(x.size()));
  if (j.contains("velocities")) {
    const std::vector<double> v = j.at("velocities").get<std::vector<double>>();
    s.velocities = Eigen::Map<const VecX>(v.data(), static_cast<Index>(v.size()));
  }
  const nlohmann::json& m = j.at("multipliers");
  for (int b = 0; b < model.n_bodies() && b < static_cast<int>(m.size()); ++b)
    if (model.constrained(b))
      model.set_multipliers(b, m[b].at("p").get<std::vector<double>>(), m[b].at("T").get<std::vector<double>>());
  s.history_rows = j.value("history_rows", "");
  for (const auto& f : j.at("frames")) s.frames.emplace_back(f.at(0).get<double>(), f.at(1).get<std::string>());
  return s;
}

}  // namespace

RunReport run_case(const FormingCase& spec, const RunOptions& options) {
  options.validate();
  const Clock::time_point t_start = Clock::now();
  int grid_body = 0;
  if (!options.grid_ply.empty()) {
    grid_body = spec.find_ply(options.grid_ply);
    if (grid_body < 0) throw UsageError("--grid-ply: no ply named '" + options.grid_ply + "' in " + spec.file);
  }

  Model model = build_model(spec);
  const std::vector<Prescription> prescribed = prescriptions(spec, model);
  const Tool tool = find_tool(spec, model);
  const CaseLoads loads = build_loads(spec, model);
  const VecX X = model.reference_positions();
  const double t_build = seconds_since(t_start);

  StaticOptions so;
  so.max_iterations = spec.solver.max_iterations;
  so.residual_tol_rel = spec.solver.tolerance;
  so.line_search = spec.solver.line_search;
  so.min_increment = spec.solver.min_increment;
  so.validate();
  UzawaOptions uzawa;
  uzawa.tolerance = spec.solver.constraint_tolerance;

  io::AtomicOutputDir out(options.out_dir);
  std::vector<std::pair<double, std::string>> frames;
  double t_write = 0.0, t_solve = 0.0;
  auto write_frame = [&](int k, double lambda, const VecX& x) {
    const Clock::time_point t0 = Clock::now();
    io::write_vtu(out.path(step_name(k)), tessellate(spec, model, x));
    // A restarted run with other step counts may reuse a name: the new frame replaces it.
    frames.erase(std::remove_if(frames.begin(), frames.end(), [&](const auto& f) { return f.second == step_name(k); }),
                 frames.end());
    frames.emplace_back(lambda, step_name(k));
    t_write += seconds_since(t0);
  };

  std::ostringstream history;
  io::CsvWriter h(history, {"step", "load_factor", "tool_ux", "tool_uy", "tool_uz", "tool_fx", "tool_fy", "tool_fz",
                            "strain_energy", "newton_iterations", "cutbacks", "residual"});
  const std::size_t history_header = history.str().size();  // rows after it go into restart.json
  auto history_row = [&](int k, double lambda, const VecX& x, const VecX& reactions, int iterations, int cutbacks,
                         double residual) {
    const ToolState ts = tool_state(tool, x, X, reactions);
    const Assembly a = model.assemble(x, false);
    h.begin_row().add(k).add(lambda);
    for (int c = 0; c < 3; ++c) h.add(ts.displacement[c]);
    for (int c = 0; c < 3; ++c) h.add(ts.force[c]);
    h.add(a.energy).add(iterations).add(cutbacks).add(residual).end_row();
    return ts;
  };

  // Dynamics: mass matrix, integrator settings, velocities (start at rest).
  const bool dynamic = spec.solver.dynamic;
  linalg::SparseMatrix mass;
  DynamicOptions dyn;
  VecX v = VecX::Zero(model.n_dofs());
  if (dynamic) {
    std::vector<double> density;
    for (const CasePly& p : spec.plies) density.push_back(spec.materials.at(static_cast<std::size_t>(p.material_index)).density);
    mass = mass_matrix(model, density);
    dyn.integrator = parse_integrator(spec.solver.integrator, "solver integrator");
    dyn.rho_inf = spec.solver.rho_inf;
    dyn.initial_dt = spec.solver.time_step > 0.0 ? spec.solver.time_step : spec.solver.end_time / (10.0 * spec.solver.steps);
    dyn.max_dt = dyn.initial_dt;
    dyn.min_dt = dyn.initial_dt * spec.solver.min_increment * 1e-2;
    dyn.max_iterations = spec.solver.max_iterations;
    dyn.residual_tol_rel = spec.solver.tolerance;
    dyn.line_search = spec.solver.line_search;
    dyn.keep_step_records = true;
  }
  // Restart state, written straight into the final folder with every frame (so it
  // survives a run that is killed before its outputs are committed).
  const std::string restart_path = (std::filesystem::path(options.out_dir) / "restart.json").string();
  RestartState restart;
  VecX x = X;
  double lambda_start = 0.0;
  const int n_steps = spec.solver.steps;
  int first_step = 1;
  if (options.restart) {
    restart = read_restart(restart_path, spec, model);
    if (restart.positions.size() != model.n_dofs()) throw InputError(restart_path + ": wrong number of positions");
    x = restart.positions;
    if (dynamic && restart.velocities.size() == model.n_dofs()) v = restart.velocities;
    lambda_start = restart.load_factor;
    while (first_step <= n_steps && double(first_step) / n_steps <= lambda_start * (1.0 + 1e-12)) ++first_step;
    // Earlier frames still present in the folder stay in the collection.
    for (const auto& [lam, name] : restart.frames)
      if (std::filesystem::exists(std::filesystem::path(options.out_dir) / name)) frames.emplace_back(lam, name);
    history << restart.history_rows;
    cli::status(options.quiet, "simform: restarting from load factor " + std::to_string(lambda_start) + " (step " +
                                   std::to_string(restart.step) + " of the earlier run)");
  } else {
    history_row(0, 0.0, x, VecX::Zero(model.n_dofs()), 0, 0, 0.0);
    write_frame(0, 0.0, x);
  }
  auto save_restart = [&](int k, double lambda) {
    restart.step = k;
    restart.load_factor = lambda;
    restart.positions = x;
    restart.velocities = dynamic ? v : VecX();
    restart.history_rows = history.str().substr(history_header);
    restart.frames = frames;
    std::error_code ec;
    std::filesystem::create_directories(options.out_dir, ec);
    write_restart(restart_path, spec, model, restart);
  };

  // Displacement of largest magnitude over the nodes (mm).
  const auto max_displacement = [&](const VecX& xs) {
    Vec3 largest = Vec3::Zero();
    for (int b = 0; b < model.n_bodies(); ++b)
      for (Index nd = 0; nd < model.ply(b).n_nodes(); ++nd) {
        Vec3 u;
        for (int c = 0; c < 3; ++c) u[c] = xs[model.dof(b, nd, 0, c)] - X[model.dof(b, nd, 0, c)];
        if (u.norm() > largest.norm()) largest = u;
      }
    return largest;
  };
  RunReport report;
  report.status = RunReport::Status::kConverged;
  int last_written = 0;
  // A converged step k at load factor lambda: its history row and the report fields.
  const auto record_step = [&](int k, double lambda, const VecX& reactions, int iterations, int cutbacks,
                               double residual) {
    const ToolState ts = history_row(k, lambda, x, reactions, iterations, cutbacks, residual);
    report.max_displacement = max_displacement(x);
    report.steps_converged = k;
    report.load_factor = lambda;
    report.final_residual = residual;
    report.tool_displacement = ts.displacement;
    report.tool_force = ts.force;
  };
  // Frame k of the current state, and the restart file that points at it.
  const auto write_step = [&](int k, double lambda) {
    write_frame(k, lambda, x);
    last_written = k;
    save_restart(k, lambda);
  };
  if (first_step > n_steps) {
    report.steps_converged = n_steps;
    report.load_factor = lambda_start;
  }
  if (spec.solver.arc_length > 0.0) {
    // Arc-length control: one continuation through the whole load history.
    if (options.restart) throw UsageError("--restart: not available with solver control arc_length");
    ArcLengthOptions ao;
    ao.arc_length = spec.solver.arc_length;
    ao.max_arc = 10.0 * spec.solver.arc_length;
    ao.min_arc = spec.solver.arc_length * spec.solver.min_increment;
    ao.max_steps = n_steps;
    ao.max_attempts = 4 * n_steps;
    ao.max_iterations = spec.solver.max_iterations;
    ao.residual_tol_rel = spec.solver.tolerance;
    ao.max_load_factor = 1.0;
    const LoadFunction proportional = [&](double lam, const VecX& xs, bool want_tangent) {
      return loads.at(model, lam, xs, want_tangent);
    };
    int k = 0;
    const auto on_point = [&](const ArcLengthPoint& pt) {
      ++k;
      x = pt.x;
      const VecX reactions = model.assemble(x, false).force - loads.at(model, pt.lambda, x, false).force;
      record_step(k, pt.lambda, reactions, pt.iterations, 0, pt.residual);
      report.total_iterations += pt.iterations;
      std::ostringstream os;
      os << "simform: arc-length step " << k << "  load factor " << pt.lambda << "  Newton " << pt.iterations
         << "  |r| " << sci(pt.residual) << " N  max |u| " << sci(report.max_displacement.norm()) << " mm";
      cli::status(options.quiet, os.str());
      if (k % spec.output.every == 0) write_step(k, pt.lambda);
      return spec.solver.stop_displacement > 0.0 && max_displacement(x).norm() >= spec.solver.stop_displacement;
    };
    const ArcLengthResult ar = solve_arc_length(model, x, targets(prescribed, 0.0), proportional, loads.follower, ao,
                                                on_point);
    const bool reached = report.load_factor >= 1.0 ||
                         (spec.solver.stop_displacement > 0.0 && max_displacement(x).norm() >= spec.solver.stop_displacement);
    if (!(ar.completed && reached)) {
      report.status = RunReport::Status::kNotConverged;
      report.message = "arc-length continuation ended at load factor " + std::to_string(report.load_factor) + ": " +
                       ar.message + "; results up to arc-length step " + std::to_string(report.steps_converged) +
                       " are written. Try a smaller arc_length or more steps";
    } else if (last_written != k) {
      write_step(k, report.load_factor);
    }
  }
  for (int k = first_step; k <= n_steps && spec.solver.arc_length == 0.0; ++k) {
    const double lambda = double(k) / n_steps;
    const Clock::time_point t0 = Clock::now();
    // Within the step the solver's factor s in [0, 1] runs from the previous load
    // factor to this one.
    const double lambda_prev = k == first_step ? lambda_start : double(k - 1) / n_steps;
    const LoadFunction step_load = [&](double sub, const VecX& xs, bool want_tangent) {
      return loads.at(model, lambda_prev + sub * (lambda - lambda_prev), xs, want_tangent);
    };
    StaticResult r;
    if (dynamic) {
      // Inertia: integrate over the output interval [t_prev, t], load factor t / end_time.
      DynamicOptions d = dyn;
      d.start_time = lambda_prev * spec.solver.end_time;
      d.end_time = lambda * spec.solver.end_time;
      std::vector<TimedDof> moving;
      for (const Prescription& p : prescribed)
        moving.push_back({p.dof, [p, T = spec.solver.end_time](double t) {
                            return p.reference + p.displacement * ramp_value(p.ramp, std::clamp(t / T, 0.0, 1.0));
                          }});
      const ExternalForceFn ext = [&](double t, const VecX& xs, bool want_tangent) {
        return loads.at(model, t / spec.solver.end_time, xs, want_tangent);
      };
      const DynamicResult dr = solve_dynamic(model, mass, x, v, moving, ext, d);
      r.positions = dr.positions;
      r.reactions = dr.reactions;
      r.report.total_iterations = dr.report.total_iterations;
      r.report.n_cutbacks = dr.report.n_cutbacks;
      r.report.status = dr.report.ok() ? StaticReport::Status::kConverged : StaticReport::Status::kStepFailed;
      r.report.message = dr.report.ok() ? std::string() : dr.report.message;
      double last = 0.0;
      for (auto it = dr.report.steps.rbegin(); it != dr.report.steps.rend(); ++it)
        if (it->converged && !it->residual_norms.empty()) {
          last = it->residual_norms.back();
          break;
        }
      StepRecord rec;
      rec.converged = dr.report.ok();
      rec.residual_norms.push_back(last);
      r.report.steps.push_back(rec);
      if (dr.report.ok()) v = dr.velocities;
    } else {
      UzawaReport uz;
      r = solve_static_constrained(model, x, targets(prescribed, lambda), step_load, loads.follower, so, uzawa, &uz);
      report.multiplier_updates += uz.updates;
    }
    t_solve += seconds_since(t0);
    report.total_iterations += r.report.total_iterations;
    if (!r.report.ok()) {
      report.status = RunReport::Status::kNotConverged;
      std::ostringstream os;
      os << "step " << k << " of " << n_steps << " (load factor " << lambda << ") did not converge: "
         << r.report.message << "; results up to step " << (k - 1)
         << " are written. Try more steps, a larger max_iterations or a smaller min_increment";
      report.message = os.str();
      cli::status(options.quiet, "simform: step " + std::to_string(k) + " failed: " + r.report.message);
      break;
    }
    x = r.positions;
    double residual = 0.0;
    for (auto it = r.report.steps.rbegin(); it != r.report.steps.rend(); ++it)
      if (it->converged && !it->residual_norms.empty()) {
        residual = it->residual_norms.back();
        break;
      }
    record_step(k, lambda, r.reactions, r.report.total_iterations, r.report.n_cutbacks, residual);
    std::ostringstream os;
    os << "simform: step " << k << "/" << n_steps;
    if (dynamic)
      os << "  t " << lambda * spec.solver.end_time << " s";
    else
      os << "  load factor " << lambda;
    os << "  Newton "
       << r.report.total_iterations << (r.report.n_cutbacks ? " (" + std::to_string(r.report.n_cutbacks) + " cut-backs)" : "")
       << "  |r| " << sci(residual) << " N  max |u| " << sci(report.max_displacement.norm()) << " mm";
    cli::status(options.quiet, os.str());
    const bool stop_now = options.stop_after > 0 && k - first_step + 1 >= options.stop_after && k < n_steps;
    if (k % spec.output.every == 0 || k == n_steps || stop_now) write_step(k, lambda);
    if (stop_now) {
      report.status = RunReport::Status::kStopped;
      report.message = "stopped after step " + std::to_string(k) + " of " + std::to_string(n_steps) +
                       " (--stop-after); continue with --restart";
      cli::status(options.quiet, "simform: " + report.message);
      break;
    }
  }
  if (!report.ok() && report.steps_converged > last_written) {
    write_step(report.steps_converged, report.load_factor);
  }

  const Clock::time_point t_out = Clock::now();
  io::write_pvd(out.path("result.pvd"), frames);
  io::write_file_atomic(out.path("history.csv"), history.str());
  // The grid file is written after the folder is committed (it may lie inside it).
  const bool finished = report.status == RunReport::Status::kConverged;
  const bool write_grid_file = !options.grid_out.empty() && finished;
  if (!options.grid_out.empty() && !finished)
    cli::status(options.quiet, "simform: not writing " + options.grid_out + " (the run did not converge)");
  const std::string grid_note = write_grid_file ? options.grid_out : std::string();
  t_write += seconds_since(t_out);
  report.seconds = seconds_since(t_start);

  nlohmann::json j;
  j["tool"] = "simform run";
  j["version"] = SF_VERSION;
  j["command_line"] = options.command_line;
  j["inputs"] = {{"case", spec.file}};
  j["parameters"] = parameters_json(spec, model);
  j["analysis"] = dynamic ? "dynamic (" + spec.solver.integrator + ", no contact)"
                 : loads.follower ? "quasi-static, follower loads (no contact)"
                                  : "quasi-static (no contact)";
  if (dynamic) j["time"] = {{"end_time_s", spec.solver.end_time}, {"time_s", report.load_factor * spec.solver.end_time}};
  j["multiplier_updates"] = report.multiplier_updates;
  j["status"] = finished ? "converged" : report.ok() ? "stopped" : "not_converged";
  j["message"] = finished ? report.brief() : report.message;
  j["restart"] = {{"file", "restart.json"}, {"restarted", options.restart}, {"from_load_factor", lambda_start}};
  j["steps"] = {{"requested", n_steps}, {"converged", report.steps_converged}, {"written", frames.size()}};
  j["load_factor"] = report.load_factor;
  j["final_residual"] = report.final_residual;
  j["newton_iterations"] = report.total_iterations;
  j["tool_edge"] = {{"edge", tool.label},
               {"displacement", {report.tool_displacement.x(), report.tool_displacement.y(), report.tool_displacement.z()}},
               {"force", {report.tool_force.x(), report.tool_force.y(), report.tool_force.z()}}};
  j["max_displacement"] = {report.max_displacement.x(), report.max_displacement.y(), report.max_displacement.z()};
  nlohmann::json lj = nlohmann::json::array();
  for (const CaseLoad& l : spec.loads) {
    nlohmann::json e;
    switch (l.kind) {
      case CaseLoad::Kind::kPressure:
        e = {{"pressure_MPa", l.value}, {"ply", l.ply}, {"face", l.top ? "top" : "bottom"}, {"follower", l.follower}};
        break;
      case CaseLoad::Kind::kGravity:
        e = {{"gravity_mm_s2", {l.vector.x(), l.vector.y(), l.vector.z()}}};
        break;
      case CaseLoad::Kind::kEdgeForce:
        e = {{"edge_force_N", {l.vector.x(), l.vector.y(), l.vector.z()}}, {"ply", l.ply}, {"edge", to_string(l.side)}};
        break;
      case CaseLoad::Kind::kPointForce:
        e = {{"point_force_N", {l.vector.x(), l.vector.y(), l.vector.z()}}, {"ply", l.ply}, {"node", {l.node_i, l.node_j}}};
        break;
    }
    e["ramp"] = to_string(l.ramp);
    lj.push_back(e);
  }
  j["loads"] = lj;
  j["timings_s"] = {{"build", t_build}, {"solve", t_solve}, {"write", t_write}, {"total", report.seconds}};
  nlohmann::json outputs = {"result.pvd", "history.csv", "summary.json"};
  for (const auto& f : frames) outputs.push_back(f.second);
  j["outputs"] = outputs;
  j["grid_out"] = grid_note.empty() ? nlohmann::json() : nlohmann::json(grid_note);
  j["units"] = {{"length", "mm"}, {"force", "N"}, {"stress", "MPa"}, {"energy", "N mm"}, {"note", spec.units}};
  io::write_json(out.path("summary.json"), j);
  out.commit();
  if (write_grid_file) {
    const std::filesystem::path parent = std::filesystem::path(options.grid_out).parent_path();
    std::error_code ec;
    if (!parent.empty()) std::filesystem::create_directories(parent, ec);
    if (ec) throw Error(options.grid_out + ": cannot create folder " + parent.string() + " (" + ec.message() + ")");
    write_grid(options.grid_out, spec, model, grid_body, x, options.grid_marks);
  }
  return report;
}

}  // namespace sf::forming
