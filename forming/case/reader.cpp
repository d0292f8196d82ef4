#include "forming/case/reader.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <tuple>

#include "common/core/error.hpp"
#include "forming/case/checks.hpp"
#include "forming/case/contact_reader.hpp"
#include "forming/case/diaphragm_reader.hpp"
#include "forming/case/model_checks.hpp"
#include "forming/case/sheet_keys.hpp"
#include "forming/case/yaml_reader.hpp"

namespace sf::forming {

using case_yaml::describe;
using case_yaml::pair_of;
using case_yaml::place_of;
using case_yaml::ply_of;
using case_yaml::ramp_of;
using case_yaml::Reader;
using case_yaml::vector3;

namespace {

const std::vector<std::string> kTopKeys = {"units",     "materials", "plies", "laminates", "boundary_conditions",
                                           "loads",     "solver",    "tools", "contact",   "output",
                                           "diaphragms"};

// The law of material `what` under key `law` (neo_hookean: {E, nu} or {mu, lambda});
// false (with a problem) when it cannot be read or the law rejects the constants.
bool read_neo_hookean(Reader& r, const std::string& what, const YAML::Node& law, const YAML::Node& p, CaseMaterial& m) {
  const std::string lw = what + " neo_hookean";
  m.kind = CaseMaterial::Kind::kNeoHookean;
  if (!r.mapping(p, lw, {"E", "nu", "mu", "lambda"})) return false;
  const bool young = p["E"].IsDefined() || p["nu"].IsDefined();
  const bool lame = p["mu"].IsDefined() || p["lambda"].IsDefined();
  if (young == lame) {
    r.problem(ProblemKind::kWrongType, law, lw + ": give either {E, nu} or {mu, lambda}");
    return false;
  }
  try {
    if (young) {
      const auto E = r.number(r.required(p, "E", lw), lw + " E");
      const auto nu = r.number(r.required(p, "nu", lw), lw + " nu");
      if (!E || !nu) return false;
      m.neo_hookean = NeoHookeanParams::from_young_poisson(*E, *nu);
      m.given_as = "E, nu";
    } else {
      const auto mu = r.number(r.required(p, "mu", lw), lw + " mu");
      const auto la = r.number(r.required(p, "lambda", lw), lw + " lambda");
      if (!mu || !la) return false;
      m.neo_hookean = NeoHookeanParams{*mu, *la};
      m.neo_hookean.validate();
      m.given_as = "mu, lambda";
    }
  } catch (const InputError& e) {
    r.problem(ProblemKind::kOutOfRange, law, what + ": " + e.what());
    return false;
  }
  return true;
}

// The Mooney-Rivlin law of material `what` ({c10, c01, nu} or {c10, c01, kappa}), as
// read_neo_hookean().
bool read_mooney_rivlin(Reader& r, const std::string& what, const YAML::Node& law, const YAML::Node& p,
                        CaseMaterial& m) {
  const std::string lw = what + " mooney_rivlin";
  m.kind = CaseMaterial::Kind::kMooneyRivlin;
  if (!r.mapping(p, lw, {"c10", "c01", "nu", "kappa"})) return false;
  if (p["nu"].IsDefined() == p["kappa"].IsDefined()) {
    r.problem(ProblemKind::kWrongType, law, lw + ": give {c10, c01} and either nu or kappa (MPa)");
    return false;
  }
  try {
    const auto c10 = r.number(r.required(p, "c10", lw), lw + " c10");
    const auto c01 = r.number(r.required(p, "c01", lw), lw + " c01");
    if (!c10 || !c01) return false;
    if (p["nu"].IsDefined()) {
      const auto nu = r.number(p["nu"], lw + " nu");
      if (!nu) return false;
      m.mooney_rivlin = MooneyRivlinParams::from_poisson(*c10, *c01, *nu);
      m.given_as = "c10, c01, nu";
    } else {
      const auto kappa = r.number(p["kappa"], lw + " kappa");
      if (!kappa) return false;
      m.mooney_rivlin = MooneyRivlinParams::from_bulk(*c10, *c01, *kappa);
      m.given_as = "c10, c01, kappa";
    }
    m.mooney_rivlin.validate();
  } catch (const InputError& e) {
    r.problem(ProblemKind::kOutOfRange, law, what + ": " + e.what());
    return false;
  }
  return true;
}

// The transversely isotropic law ({E_f, E_T, G_L, G_T} or {mu_T, mu_L, kappa_f,
// lambda}; always the compressible form), as read_neo_hookean().
bool read_transversely_isotropic(Reader& r, const std::string& what, const YAML::Node& law, const YAML::Node& p,
                                 CaseMaterial& m) {
  const std::string lw = what + " transversely_isotropic";
  m.kind = CaseMaterial::Kind::kTransverselyIsotropic;
  if (!r.mapping(p, lw, {"mu_T", "mu_L", "kappa_f", "lambda", "E_f", "E_T", "G_L", "G_T"})) return false;
  const bool engineering = p["E_f"].IsDefined() || p["E_T"].IsDefined() || p["G_L"].IsDefined() || p["G_T"].IsDefined();
  const bool direct =
      p["mu_T"].IsDefined() || p["mu_L"].IsDefined() || p["kappa_f"].IsDefined() || p["lambda"].IsDefined();
  if (engineering == direct) {
    r.problem(ProblemKind::kWrongType, law, lw + ": give either {E_f, E_T, G_L, G_T} or {mu_T, mu_L, kappa_f, lambda}");
    return false;
  }
  try {
    if (engineering) {
      TransverselyIsotropicEngineering e;
      const auto Ef = r.number(r.required(p, "E_f", lw), lw + " E_f");
      const auto Et = r.number(r.required(p, "E_T", lw), lw + " E_T");
      const auto Gl = r.number(r.required(p, "G_L", lw), lw + " G_L");
      const auto Gt = r.number(r.required(p, "G_T", lw), lw + " G_T");
      if (!Ef || !Et || !Gl || !Gt) return false;
      e.E_f = *Ef;
      e.E_T = *Et;
      e.G_L = *Gl;
      e.G_T = *Gt;
      e.incompressible = false;
      m.ti = e.to_params();
      m.given_as = "E_f, E_T, G_L, G_T";
    } else {
      const auto mt = r.number(r.required(p, "mu_T", lw), lw + " mu_T");
      const auto ml = r.number(r.required(p, "mu_L", lw), lw + " mu_L");
      const auto kf = r.number(r.required(p, "kappa_f", lw), lw + " kappa_f");
      const auto la = r.number(r.required(p, "lambda", lw), lw + " lambda");
      if (!mt || !ml || !kf || !la) return false;
      m.ti.mu_T = *mt;
      m.ti.mu_L = *ml;
      m.ti.kappa_f = *kf;
      m.ti.lambda = *la;
      m.ti.incompressible = false;
      m.ti.validate();
      m.given_as = "mu_T, mu_L, kappa_f, lambda";
    }
  } catch (const InputError& e) {
    r.problem(ProblemKind::kOutOfRange, law, what + ": " + e.what());
    return false;
  }
  return true;
}

void read_material(Reader& r, const std::string& name, const YAML::Node& key, const YAML::Node& body,
                   FormingCase& spec) {
  const std::string what = "material '" + name + "'";
  CaseMaterial m;
  m.name = name;
  m.place = place_of(key);
  if (!r.mapping(
          body, what,
          {"neo_hookean", "mooney_rivlin", "transversely_isotropic", "density", "incompressible", "inextensible"}))
    return;
  std::size_t extras = 0;
  if (body["density"].IsDefined()) {
    ++extras;
    if (const auto rho = r.positive(body["density"], what + " density", "t/mm^3, e.g. 1.5e-9 for GF/PP"))
      m.density = *rho;
  }
  for (const char* flag : {"incompressible", "inextensible"}) {
    if (!body[flag].IsDefined()) continue;
    ++extras;
    if (const auto v = r.boolean(body[flag], what + " " + flag))
      (std::string(flag) == "incompressible" ? m.incompressible : m.inextensible) = *v;
  }
  if (body.size() != extras + 1) {
    r.problem(ProblemKind::kWrongType, key,
              what + ": expected exactly one law (neo_hookean, mooney_rivlin or transversely_isotropic)");
    return;
  }
  auto law = body.begin();
  const auto is_law = [](const std::string& k) {
    return k == "neo_hookean" || k == "mooney_rivlin" || k == "transversely_isotropic";
  };
  while (law != body.end() && !is_law(law->first.Scalar())) ++law;
  if (law == body.end()) return;
  if (m.inextensible && law->first.Scalar() != "transversely_isotropic")
    r.problem(ProblemKind::kUnsupported, body["inextensible"],
              what + ": inextensible needs fibres (a transversely_isotropic law)");
  const std::string law_name = law->first.Scalar();
  const YAML::Node p = law->second;
  if (!is_law(law_name)) return;  // reported above
  const bool ok = law_name == "neo_hookean"     ? read_neo_hookean(r, what, law->first, p, m)
                  : law_name == "mooney_rivlin" ? read_mooney_rivlin(r, what, law->first, p, m)
                                                : read_transversely_isotropic(r, what, law->first, p, m);
  if (ok) spec.materials.push_back(m);
}

void read_ply(Reader& r, const YAML::Node& n, int index, FormingCase& spec) {
  std::string what = "ply " + std::to_string(index + 1);
  if (!r.mapping(n, what, {"name", "origin", "size", "thickness", "elements", "angle", "material", "plane_strain"}))
    return;
  CasePly ply;
  ply.place = place_of(n);
  bool ok = true;
  if (const auto name = r.text(r.required(n, "name", what), what + " name")) {
    ply.name = *name;
    what = "ply '" + ply.name + "'";
    if (spec.find_ply(ply.name) >= 0) {
      r.problem(ProblemKind::kDuplicate, n["name"], what + ": name used by an earlier ply");
      ok = false;
    }
  } else {
    ok = false;
  }
  if (const YAML::Node o = n["origin"]; o.IsDefined()) {
    if (!case_yaml::is_sequence(o) || o.size() != 3) {
      r.problem(ProblemKind::kWrongType, o, what + " origin: expected [x, y, z] (mm), found " + describe(o));
      ok = false;
    } else {
      for (int i = 0; i < 3; ++i) {
        const auto v = r.number(o[i], what + " origin");
        if (v)
          ply.origin[i] = *v;
        else
          ok = false;
      }
    }
  }
  ok = sheet_keys::read_size(r, n, what, ply) && ok;
  ok = sheet_keys::read_thickness(r, n, "thickness", what, true, ply.thickness) && ok;
  ok = sheet_keys::read_elements(r, n, what, ply) && ok;
  ok = r.optional_key(n, "angle", ply.angle_deg, [&](const YAML::Node& a) {
    return r.number(a, what + " angle (degrees)");
  }) && ok;
  ok = sheet_keys::read_plane_strain(r, n, what, ply) && ok;
  ok = sheet_keys::read_material(r, n, what, true, spec, ply) && ok;
  if (ok) spec.plies.push_back(ply);
}

std::optional<PlySide> side_of(Reader& r, const YAML::Node& n, const std::string& what, bool allow_bottom) {
  if (case_yaml::is_scalar(n)) {
    const std::string& s = n.Scalar();
    if (s == "x0") return PlySide::kX0;
    if (s == "x1") return PlySide::kX1;
    if (s == "y0") return PlySide::kY0;
    if (s == "y1") return PlySide::kY1;
    if (allow_bottom && s == "bottom") return PlySide::kBottom;
  }
  r.problem(ProblemKind::kWrongType, n,
            what + ": expected " + std::string(allow_bottom ? "x0, x1, y0, y1 or bottom" : "x0, x1, y0 or y1") +
                ", found " + describe(n));
  return std::nullopt;
}

void read_boundary(Reader& r, const YAML::Node& n, int index, FormingCase& spec) {
  const std::string what = "boundary condition " + std::to_string(index + 1);
  if (!r.mapping(n, what, {"clamp", "displacement", "symmetry"})) return;
  if (n.size() != 1) {
    r.problem(ProblemKind::kWrongType, n, what + ": expected exactly one of clamp, displacement, symmetry");
    return;
  }
  const auto kv = n.begin();
  const std::string kind = kv->first.Scalar();
  const YAML::Node b = kv->second;
  if (kind != "clamp" && kind != "displacement" && kind != "symmetry") return;  // reported above
  const std::string bw = what + " (" + kind + ")";
  CaseBoundary bc;
  bc.place = place_of(kv->first);
  std::vector<std::string> keys = {"ply"};
  if (kind == "clamp") {
    bc.kind = CaseBoundary::Kind::kClamp;
    keys.push_back("edge");
  } else if (kind == "displacement") {
    bc.kind = CaseBoundary::Kind::kDisplacement;
    keys.insert(keys.end(), {"edge", "value", "ramp"});
  } else {
    bc.kind = CaseBoundary::Kind::kSymmetry;
    keys.push_back("plane");
  }
  if (!r.mapping(b, bw, keys)) return;
  bool ok = ply_of(r, b, bw, spec, bc.ply, bc.ply_index);
  const bool symmetry = bc.kind == CaseBoundary::Kind::kSymmetry;
  const std::string side_key = symmetry ? "plane" : "edge";
  ok = r.required_key(b, side_key, bw, bc.side, [&](const YAML::Node& s) {
    return side_of(r, s, bw + " " + side_key, symmetry);
  }) && ok;
  if (bc.kind == CaseBoundary::Kind::kDisplacement) {
    const YAML::Node v = r.required(b, "value", bw);
    if (v.IsDefined()) {
      if (!case_yaml::is_sequence(v) || v.size() != 3) {
        r.problem(ProblemKind::kWrongType, v,
                  bw + " value: expected [ux, uy, uz] (mm; ~ for a free component), found " + describe(v));
        ok = false;
      } else {
        int given = 0;
        for (int i = 0; i < 3; ++i) {
          if (case_yaml::is_null(v[i]) || (case_yaml::is_scalar(v[i]) && v[i].Scalar() == "free")) continue;
          const auto u = r.number(v[i], bw + " value");
          if (u) {
            bc.value[i] = *u;
            ++given;
          } else
            ok = false;
        }
        if (ok && given == 0) {
          r.problem(ProblemKind::kMissing, v, bw + " value: every component is free; give at least one");
          ok = false;
        }
      }
    } else
      ok = false;
    if (!ramp_of(r, b, bw, bc.ramp)) ok = false;
  }
  if (ok) spec.boundaries.push_back(bc);
}

// The keys of each load kind (the ply is read before); false (with problems) when one
// is missing or bad.
bool read_pressure(Reader& r, const YAML::Node& b, const std::string& lw, CaseLoad& load) {
  bool ok = true;
  if (const YAML::Node f = r.required(b, "face", lw); f.IsDefined()) {
    if (case_yaml::is_scalar(f) && (f.Scalar() == "top" || f.Scalar() == "bottom")) {
      load.top = f.Scalar() == "top";
    } else {
      r.problem(ProblemKind::kWrongType, f, lw + " face: expected top or bottom, found " + describe(f));
      ok = false;
    }
  } else
    ok = false;
  ok = r.required_key(b, "value", lw, load.value, [&](const YAML::Node& v) {
    return r.number(v, lw + " value (MPa)");
  }) && ok;
  ok = r.optional_key(b, "follower", load.follower, [&](const YAML::Node& v) {
    return r.boolean(v, lw + " follower");
  }) && ok;
  return ok;
}

// Gravity also needs every material's density (reported at the load's key).
bool read_gravity(Reader& r, const YAML::Node& b, const YAML::Node& key, const std::string& lw, const FormingCase& spec,
                  CaseLoad& load) {
  bool ok = true;
  const YAML::Node a = b["acceleration"];
  if (a.IsDefined()) {
    if (const auto g = vector3(r, a, lw + " acceleration", "mm/s^2"))
      load.vector = *g;
    else
      ok = false;
  } else {
    load.vector = Vec3(0.0, 0.0, -9810.0);
  }
  for (const CaseMaterial& m : spec.materials)
    if (!(m.density > 0.0)) {
      r.problem(ProblemKind::kMissing, key,
                lw + ": material '" + m.name + "' has no density (t/mm^3, e.g. density: 1.5e-9)");
      ok = false;
    }
  return ok;
}

bool read_edge_force(Reader& r, const YAML::Node& b, const std::string& lw, CaseLoad& load) {
  bool ok = true;
  ok = r.required_key(b, "edge", lw, load.side, [&](const YAML::Node& e) {
    return side_of(r, e, lw + " edge", false);
  }) && ok;
  ok = r.required_key(b, "force", lw, load.vector, [&](const YAML::Node& f) {
    return vector3(r, f, lw + " force", "N, total over the edge");
  }) && ok;
  return ok;
}

// The node must lie on the ply's grid (0..elements each way).
bool read_point_force(Reader& r, const YAML::Node& b, const std::string& lw, const FormingCase& spec, CaseLoad& load) {
  bool ok = true;
  if (const YAML::Node nd = r.required(b, "node", lw); nd.IsDefined()) {
    if (pair_of(r, nd, lw + " node [i, j]")) {
      const int ply = load.ply_index;
      const int n1 = ply >= 0 ? spec.plies[ply].n1 : 1000, n2 = ply >= 0 ? spec.plies[ply].n2 : 1000;
      const auto i = r.integer(nd[0], lw + " node i (0 at x0 .. elements along x)", 0, n1);
      const auto j = r.integer(nd[1], lw + " node j (0 at y0 .. elements along y)", 0, n2);
      if (i && j) {
        load.node_i = *i;
        load.node_j = *j;
      } else
        ok = false;
    } else
      ok = false;
  } else
    ok = false;
  if (const YAML::Node l = b["layer"]; l.IsDefined()) {
    if (const auto k = r.choice(l, lw + " layer", {"bottom", "top", "both"}, "bottom, top or both"))
      load.layer = *k == 2 ? -1 : *k;  // 0 bottom, 1 top, -1 both
    else
      ok = false;
  }
  ok = r.required_key(b, "force", lw, load.vector, [&](const YAML::Node& f) {
    return vector3(r, f, lw + " force", "N");
  }) && ok;
  return ok;
}

void read_load(Reader& r, const YAML::Node& n, int index, FormingCase& spec) {
  const std::string what = "load " + std::to_string(index + 1);
  const std::vector<std::string> kinds = {"pressure", "gravity", "edge_force", "point_force"};
  if (!r.mapping(n, what, kinds)) return;
  if (n.size() != 1) {
    r.problem(ProblemKind::kWrongType, n,
              what + ": expected exactly one of pressure, gravity, edge_force, point_force");
    return;
  }
  const auto kv = n.begin();
  const std::string kind = kv->first.Scalar();
  if (std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) return;  // reported above
  const YAML::Node b = kv->second;
  const std::string lw = what + " (" + kind + ")";
  CaseLoad load;
  load.place = place_of(kv->first);
  std::vector<std::string> keys = {"ramp"};
  if (kind == "pressure") {
    load.kind = CaseLoad::Kind::kPressure;
    keys.insert(keys.end(), {"ply", "face", "value", "follower"});
  } else if (kind == "gravity") {
    load.kind = CaseLoad::Kind::kGravity;
    keys.insert(keys.end(), {"acceleration"});
  } else if (kind == "edge_force") {
    load.kind = CaseLoad::Kind::kEdgeForce;
    keys.insert(keys.end(), {"ply", "edge", "force"});
  } else {
    load.kind = CaseLoad::Kind::kPointForce;
    keys.insert(keys.end(), {"ply", "node", "layer", "force"});
  }
  if (!r.mapping(b, lw, keys)) return;
  bool ok = load.kind == CaseLoad::Kind::kGravity || ply_of(r, b, lw, spec, load.ply, load.ply_index);
  switch (load.kind) {
    case CaseLoad::Kind::kPressure:
      ok = read_pressure(r, b, lw, load) && ok;
      break;
    case CaseLoad::Kind::kGravity:
      ok = read_gravity(r, b, kv->first, lw, spec, load) && ok;
      break;
    case CaseLoad::Kind::kEdgeForce:
      ok = read_edge_force(r, b, lw, load) && ok;
      break;
    case CaseLoad::Kind::kPointForce:
      ok = read_point_force(r, b, lw, spec, load) && ok;
      break;
  }
  if (!ramp_of(r, b, lw, load.ramp)) ok = false;
  if (ok) spec.loads.push_back(load);
}

void read_solver(Reader& r, const YAML::Node& n, CaseSolver& s) {
  if (!r.mapping(n, "solver",
                 {"steps", "max_iterations", "tolerance", "line_search", "min_increment", "constraint_tolerance",
                  "analysis", "end_time", "time_step", "integrator", "rho_inf", "control", "arc_length",
                  "stop_displacement", "process_time", "predictor", "linear", "stabilise", "branch_switch"}))
    return;
  bool arc = false;
  s.control_place = place_of(n["control"]);
  s.analysis_place = place_of(n["analysis"]);
  if (const YAML::Node c = n["control"]; c.IsDefined()) {
    if (case_yaml::is_scalar(c) && (c.Scalar() == "load" || c.Scalar() == "arc_length"))
      arc = c.Scalar() == "arc_length";
    else
      r.problem(ProblemKind::kWrongType, c, "solver control: expected load or arc_length, found " + describe(c));
  }
  if (arc) {
    const YAML::Node a = n["arc_length"];
    if (!a.IsDefined())
      r.problem(ProblemKind::kMissing, n["control"],
                "solver control arc_length: give arc_length (the path length per step, mm)");
    else if (const auto v = r.positive(a, "solver arc_length", "mm"))
      s.arc_length = *v;
    if (n["stop_displacement"].IsDefined())
      if (const auto v = r.positive(n["stop_displacement"], "solver stop_displacement", "mm")) s.stop_displacement = *v;
  } else {
    for (const char* key : {"arc_length", "stop_displacement"})
      if (n[key].IsDefined())
        r.problem(ProblemKind::kUnsupported, n[key],
                  std::string("solver ") + key + ": only used with control: arc_length");
  }
  if (const YAML::Node a = n["analysis"]; a.IsDefined()) {
    if (case_yaml::is_scalar(a) && (a.Scalar() == "static" || a.Scalar() == "dynamic"))
      s.dynamic = a.Scalar() == "dynamic";
    else
      r.problem(ProblemKind::kWrongType, a, "solver analysis: expected static or dynamic, found " + describe(a));
  }
  if (n["end_time"].IsDefined())
    if (const auto v = r.positive(n["end_time"], "solver end_time", "s")) s.end_time = *v;
  if (n["process_time"].IsDefined())
    if (const auto v = r.positive(n["process_time"], "solver process_time", "s, of the whole load"))
      s.process_time = *v;
  if (n["time_step"].IsDefined())
    if (const auto v = r.positive(n["time_step"], "solver time_step", "s")) s.time_step = *v;
  // Absurd durations run "forever" without a word: a forming process lasts seconds to hours.
  constexpr double kLongestProcess = 1e5;  // s (28 hours)
  for (const char* key : {"end_time", "process_time"}) {
    const double value = std::string(key) == "end_time" ? s.end_time : s.process_time;
    if (n[key].IsDefined() && value > kLongestProcess)
      r.problem(ProblemKind::kOutOfRange, n[key],
                std::string("solver ") + key + ": " + n[key].Scalar() +
                    " s is beyond any forming process (at most 1e5 s = 28 hours); check the value and its unit (s)");
  }
  if (n["time_step"].IsDefined() && s.time_step > 0.0 && s.end_time / s.time_step > 1e7)
    r.problem(ProblemKind::kOutOfRange, n["time_step"],
              "solver time_step: " + n["time_step"].Scalar() + " s makes " +
                  fmt::format("{:.3g}", s.end_time / s.time_step) +
                  " time steps over end_time (at most 1e7); give a larger time_step or a shorter end_time");
  if (const YAML::Node i = n["integrator"]; i.IsDefined()) {
    if (case_yaml::is_scalar(i) &&
        (i.Scalar() == "generalized-alpha" || i.Scalar() == "hht-alpha" || i.Scalar() == "newmark"))
      s.integrator = i.Scalar();
    else
      r.problem(ProblemKind::kWrongType, i,
                "solver integrator: expected generalized-alpha, hht-alpha or newmark, found " + describe(i));
  }
  if (n["rho_inf"].IsDefined()) {
    const auto v = r.number(n["rho_inf"], "solver rho_inf");
    if (v && !(*v >= 0.0 && *v <= 1.0))
      r.problem(ProblemKind::kOutOfRange, n["rho_inf"],
                "solver rho_inf: expected a spectral radius in [0, 1], found " + n["rho_inf"].Scalar());
    else if (v)
      s.rho_inf = *v;
  }
  for (const char* key : {"end_time", "time_step", "integrator", "rho_inf"})
    if (n[key].IsDefined() && !s.dynamic && !(n["analysis"].IsDefined() && !case_yaml::is_scalar(n["analysis"])))
      r.problem(ProblemKind::kUnsupported, n[key], std::string("solver ") + key + ": only used with analysis: dynamic");
  if (n["constraint_tolerance"].IsDefined()) {
    const auto v = r.number(n["constraint_tolerance"], "solver constraint_tolerance");
    if (v && !(*v > 0.0 && *v < 0.1))
      r.problem(
          ProblemKind::kOutOfRange, n["constraint_tolerance"],
          "solver constraint_tolerance: expected a value in (0, 0.1), found " + n["constraint_tolerance"].Scalar());
    else if (v)
      s.constraint_tolerance = *v;
  }
  if (n["steps"].IsDefined())
    if (const auto v = r.integer(n["steps"], "solver steps", 1, 100000)) s.steps = *v;
  if (n["max_iterations"].IsDefined())
    if (const auto v = r.integer(n["max_iterations"], "solver max_iterations", 1, 1000)) s.max_iterations = *v;
  if (n["tolerance"].IsDefined()) {
    const auto v = r.number(n["tolerance"], "solver tolerance");
    if (v && (*v <= 0.0 || *v >= 1.0))
      r.problem(ProblemKind::kOutOfRange, n["tolerance"],
                "solver tolerance: expected a relative residual in (0, 1), found " + n["tolerance"].Scalar());
    else if (v)
      s.tolerance = *v;
  }
  if (const YAML::Node pr = n["predictor"]; pr.IsDefined()) {
    if (case_yaml::is_scalar(pr) && (pr.Scalar() == "tangent" || pr.Scalar() == "extrapolate"))
      s.extrapolate = pr.Scalar() == "extrapolate";
    else
      r.problem(ProblemKind::kWrongType, pr,
                "solver predictor: expected tangent (default) or extrapolate (start each step from the last "
                "step's increment), found " +
                    describe(pr));
  }
  if (const YAML::Node li = n["linear"]; li.IsDefined()) {
    // iterative-ply (GMRES preconditioned per ply) is a benchmark's option only: it does
    // not converge under penalty contact (forming/solve/tangent_solver.hpp).
    if (case_yaml::is_scalar(li) && (li.Scalar() == "direct" || li.Scalar() == "iterative" || li.Scalar() == "auto"))
      s.linear = li.Scalar();
    else
      r.problem(ProblemKind::kWrongType, li,
                "solver linear: expected direct (sparse factorisation), iterative (GMRES preconditioned by an "
                "earlier tangent's factorisation) or auto (direct), found " +
                    describe(li));
  }
  if (const YAML::Node st = n["stabilise"]; st.IsDefined()) {
    s.stabilise_place = place_of(st);
    if (r.mapping(st, "solver stabilise", {"fraction", "damping", "warn_ratio"})) {
      if (st["fraction"].IsDefined() && st["damping"].IsDefined())
        r.problem(ProblemKind::kUnsupported, st["damping"],
                  "solver stabilise: give fraction (c calibrated from the first step) or damping (c in N s/mm^4), "
                  "not both");
      else if (!st["fraction"].IsDefined() && !st["damping"].IsDefined())
        r.problem(ProblemKind::kMissing, st,
                  "solver stabilise: give fraction (of the strain energy the first step may dissipate, e.g. 2e-4) "
                  "or damping (c, N s/mm^4)");
      if (st["fraction"].IsDefined()) {
        const auto v = r.number(st["fraction"], "solver stabilise fraction");
        if (v && !(*v > 0.0 && *v < 1.0))
          r.problem(ProblemKind::kOutOfRange, st["fraction"],
                    "solver stabilise fraction: expected a fraction of the strain energy in (0, 1), e.g. 2e-4, "
                    "found " +
                        st["fraction"].Scalar());
        else if (v)
          s.stabilise_fraction = *v;
      }
      if (st["damping"].IsDefined())
        if (const auto v = r.positive(st["damping"], "solver stabilise damping", "N s/mm^4"))
          s.stabilise_damping = *v;
      if (st["warn_ratio"].IsDefined())
        if (const auto v = r.positive(st["warn_ratio"], "solver stabilise warn_ratio",
                                      "dissipated over strain energy, e.g. 0.05"))
          s.stabilise_warn_ratio = *v;
    }
  }
  if (const YAML::Node bs = n["branch_switch"]; bs.IsDefined()) {
    s.branch_switch_place = place_of(bs);
    if (r.mapping(bs, "solver branch_switch", {"amplitude", "give_up_after", "retries", "last_retry_damping"})) {
      if (!bs["amplitude"].IsDefined())
        r.problem(ProblemKind::kMissing, bs,
                  "solver branch_switch: give amplitude (mm, the largest nodal displacement of the imperfection "
                  "along the critical mode, e.g. a tenth of a ply thickness)");
      else if (const auto v = r.positive(bs["amplitude"], "solver branch_switch amplitude", "mm"))
        s.branch_switch_amplitude = *v;
      if (bs["give_up_after"].IsDefined())
        if (const auto v = r.integer(bs["give_up_after"], "solver branch_switch give_up_after (failed sub-steps "
                                     "of a step before a switch; 0: cut back to min_increment first)", 0, 1000))
          s.branch_switch_give_up_after = *v;
      if (bs["retries"].IsDefined())
        if (const auto v = r.integer(bs["retries"], "solver branch_switch retries (switched retries of a failed step)",
                                     0, 100))
          s.branch_switch_retries = *v;
      if (bs["last_retry_damping"].IsDefined()) {
        if (const auto v = r.number(bs["last_retry_damping"], "solver branch_switch last_retry_damping")) {
          if (*v >= 1.0 && *v <= 1000.0)
            s.branch_switch_last_retry_damping = *v;
          else
            r.problem(ProblemKind::kOutOfRange, bs["last_retry_damping"],
                      "solver branch_switch last_retry_damping: expected a factor from 1 (the damping not raised) "
                      "to 1000 on the run's stabilisation damping, got " + std::to_string(*v));
        }
      }
    }
  }
  if (n["line_search"].IsDefined())
    if (const auto v = r.boolean(n["line_search"], "solver line_search")) s.line_search = *v;
  if (n["min_increment"].IsDefined()) {
    const auto v = r.number(n["min_increment"], "solver min_increment");
    if (v && !(*v > 0.0 && *v <= 1.0))
      r.problem(ProblemKind::kOutOfRange, n["min_increment"],
                "solver min_increment: expected a fraction of a step in (0, 1], found " + n["min_increment"].Scalar());
    else if (v)
      s.min_increment = *v;
  }
}

void read_output(Reader& r, const YAML::Node& n, CaseOutput& o) {
  if (!r.mapping(n, "output", {"every", "samples"})) return;
  if (n["every"].IsDefined())
    if (const auto v = r.integer(n["every"], "output every", 1, 100000)) o.every = *v;
  if (const YAML::Node s = n["samples"]; s.IsDefined()) {
    if (pair_of(r, s, "output samples [in-plane, through thickness]")) {
      const auto a = r.integer(s[0], "output samples in-plane", 1, 16);
      const auto b = r.integer(s[1], "output samples through the thickness", 1, 16);
      if (a) o.samples_inplane = *a;
      if (b) o.samples_thickness = *b;
    }
  }
}

// Drops the problems from index `from` on of `kind` whose name is in `defined`: a
// reference to something defined but itself bad (reported where it is defined).
void drop_unknown_names(std::vector<CaseProblem>& problems, std::size_t from, ProblemKind kind,
                        const std::set<std::string>& defined) {
  const auto follow_on = [&](const CaseProblem& p) { return p.kind == kind && defined.count(p.name) > 0; };
  problems.erase(std::remove_if(problems.begin() + static_cast<long>(from), problems.end(), follow_on), problems.end());
}

// Names of the tools listed (read or not); false when there are none.
bool ts_names(const YAML::Node& root, std::set<std::string>& names) {
  if (const YAML::Node ts = root["tools"]; ts.IsDefined() && case_yaml::is_sequence(ts))
    for (const YAML::Node& t : ts)
      if (case_yaml::is_map(t) && case_yaml::is_scalar(t["name"])) names.insert(t["name"].Scalar());
  return !names.empty();
}

void read_document(Reader& r, const YAML::Node& root, const std::string& case_dir, FormingCase& spec,
                   std::vector<CaseProblem>& problems) {
  if (!root.IsDefined() || case_yaml::is_null(root)) {
    r.problem(ProblemKind::kMissing, SourcePlace{1, 1},
              "empty case file: expected materials, plies, boundary_conditions");
    return;
  }
  if (!r.mapping(root, "case", kTopKeys)) return;
  if (const YAML::Node u = root["units"]; u.IsDefined()) {
    if (case_yaml::is_scalar(u))
      spec.units = u.Scalar();
    else
      r.problem(ProblemKind::kWrongType, u, "units: expected a note such as \"mm, N, MPa\", found " + describe(u));
  }
  if (const YAML::Node ms = r.required(root, "materials", "case"); ms.IsDefined()) {
    if (!case_yaml::is_map(ms)) {
      r.problem(ProblemKind::kWrongType, ms,
                "materials: expected a mapping of names to laws (gfpp: {transversely_isotropic: ...}), found " +
                    describe(ms));
    } else {
      std::set<std::string> seen;
      for (auto it = ms.begin(); it != ms.end(); ++it) {
        const std::string name = it->first.Scalar();
        if (!seen.insert(name).second) {
          r.problem(ProblemKind::kDuplicate, it->first, "material '" + name + "' defined twice");
          continue;
        }
        read_material(r, name, it->first, it->second, spec);
      }
      if (ms.size() == 0) r.problem(ProblemKind::kMissing, ms, "materials: expected at least one material");
    }
  }
  // Names of materials that failed to read must not also be reported as "unknown".
  std::set<std::string> material_names;
  if (const YAML::Node ms = root["materials"]; case_yaml::is_map(ms))
    for (auto it = ms.begin(); it != ms.end(); ++it) material_names.insert(it->first.Scalar());
  // Plies come from `plies`, `laminates` or both.
  const YAML::Node ps = root["laminates"].IsDefined() ? root["plies"] : r.required(root, "plies", "case");
  if (ps.IsDefined()) {
    if (!case_yaml::is_sequence(ps) || ps.size() == 0) {
      r.problem(ProblemKind::kWrongType, ps, "plies: expected a list of plies (- name: ...), found " + describe(ps));
    } else {
      for (std::size_t i = 0; i < ps.size(); ++i) {
        const std::size_t before = problems.size();
        read_ply(r, ps[i], static_cast<int>(i), spec);
        // A ply naming a material that exists but was bad: one problem is enough.
        drop_unknown_names(problems, before, ProblemKind::kUnknownMaterial, material_names);
      }
    }
  }
  if (const YAML::Node ls = root["laminates"]; ls.IsDefined()) {
    const std::size_t before = problems.size();
    read_laminates(r, ls, spec);
    drop_unknown_names(problems, before, ProblemKind::kUnknownMaterial, material_names);
  }
  std::set<std::string> ply_names;
  if (const YAML::Node listed = root["plies"]; listed.IsDefined() && case_yaml::is_sequence(listed))
    for (const YAML::Node& p : listed)
      if (case_yaml::is_map(p) && case_yaml::is_scalar(p["name"])) ply_names.insert(p["name"].Scalar());
  // A name "<laminate>.<k>" of a laminate that failed to read: its own problem is enough.
  std::set<std::string> failed_laminates;
  if (const YAML::Node ls = root["laminates"]; ls.IsDefined() && case_yaml::is_sequence(ls))
    for (const YAML::Node& l : ls)
      if (case_yaml::is_map(l) && case_yaml::is_scalar(l["name"]) &&
          std::none_of(spec.laminates.begin(), spec.laminates.end(),
                       [&](const CaseLaminate& c) { return c.name == l["name"].Scalar(); }))
        failed_laminates.insert(l["name"].Scalar());
  const auto laminate_ply = [&failed_laminates](const CaseProblem& p) {
    const std::size_t dot = p.name.rfind('.');
    return p.kind == ProblemKind::kUnknownPly && dot != std::string::npos &&
           failed_laminates.count(p.name.substr(0, dot));
  };
  // A condition or load naming a ply that exists but was bad: the ply's own problem is enough.
  auto drop_unknown_ply_problems = [&](std::size_t from) {
    drop_unknown_names(problems, from, ProblemKind::kUnknownPly, ply_names);
    problems.erase(std::remove_if(problems.begin() + static_cast<long>(from), problems.end(), laminate_ply),
                   problems.end());
  };
  if (const YAML::Node bs = r.required(root, "boundary_conditions", "case"); bs.IsDefined()) {
    if (!case_yaml::is_sequence(bs) || bs.size() == 0) {
      r.problem(ProblemKind::kWrongType, bs,
                "boundary_conditions: expected a list (- clamp: ...), found " + describe(bs));
    } else {
      for (std::size_t i = 0; i < bs.size(); ++i) {
        const std::size_t before = problems.size();
        read_boundary(r, bs[i], static_cast<int>(i), spec);
        drop_unknown_ply_problems(before);
      }
    }
  }
  if (const YAML::Node ls = root["loads"]; ls.IsDefined()) {
    if (!case_yaml::is_sequence(ls)) {
      r.problem(ProblemKind::kWrongType, ls, "loads: expected a list (- pressure: ...), found " + describe(ls));
    } else {
      for (std::size_t i = 0; i < ls.size(); ++i) {
        const std::size_t before = problems.size();
        read_load(r, ls[i], static_cast<int>(i), spec);
        drop_unknown_ply_problems(before);
      }
    }
  }
  if (const YAML::Node s = root["solver"]; s.IsDefined()) read_solver(r, s, spec.solver);
  if (const YAML::Node ts = root["tools"]; ts.IsDefined()) read_tools(r, ts, case_dir, spec);
  if (const YAML::Node ds = root["diaphragms"]; ds.IsDefined()) {
    const std::size_t before = problems.size();
    read_diaphragms(r, ds, spec);
    drop_unknown_names(problems, before, ProblemKind::kUnknownMaterial, material_names);
  }
  if (const YAML::Node cs = root["contact"]; cs.IsDefined()) {
    const std::size_t before = problems.size();
    read_contacts(r, cs, spec);
    drop_unknown_ply_problems(before);
    std::set<std::string> tool_names;
    if (ts_names(root, tool_names)) drop_unknown_names(problems, before, ProblemKind::kUnknownTool, tool_names);
  }
  if (const YAML::Node o = root["output"]; o.IsDefined()) read_output(r, o, spec.output);
}

// The values of `node` under `path`, flattened in file order (see FormingCase::fingerprint).
void flatten(const YAML::Node& node, const std::string& path, std::vector<std::pair<std::string, std::string>>& out) {
  if (case_yaml::is_map(node)) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      const std::string key = case_yaml::is_scalar(it->first) ? it->first.Scalar() : "?";
      if (path.empty() && key == "output") continue;  // output settings may change for a restart
      // and so may the solver keys that steer how a step is solved, not what is solved
      // (a run that stalled goes on with more iterations, a smaller min_increment or
      // branch switching from the restart's step onwards)
      if (restart_may_change(path.empty() ? key : path + "." + key)) continue;
      flatten(it->second, path.empty() ? key : path + "." + key, out);
    }
  } else if (case_yaml::is_sequence(node)) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      // A named item ("- name: top") is known by its name, so inserting one names it.
      const YAML::Node item = node[i];
      const std::string id =
          case_yaml::is_map(item) && case_yaml::is_scalar(item["name"]) ? item["name"].Scalar() : std::to_string(i);
      flatten(item, path + "[" + id + "]", out);
    }
    if (node.size() == 0) out.emplace_back(path, "[]");
  } else if (case_yaml::is_scalar(node)) {
    out.emplace_back(path, node.Scalar());
  } else {
    out.emplace_back(path, "null");
  }
}

// FNV-1a of a file's bytes ("" when it cannot be read).
std::string file_checksum(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::uint64_t h = 1469598103934665603ULL;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    for (std::streamsize i = 0; i < in.gcount(); ++i) {
      h ^= static_cast<unsigned char>(buf[i]);
      h *= 1099511628211ULL;
    }
  }
  char hex[20];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

}  // namespace

CaseCheck check_case_text(const std::string& text, const std::string& name) {
  CaseCheck result;
  result.spec.file = name;
  Reader r(result.problems);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    result.problems.push_back(
        {ProblemKind::kUnreadable, {e.mark.line + 1, e.mark.column + 1}, "invalid YAML: " + e.msg, {}});
    return result;
  }
  try {
    read_document(r, root, std::filesystem::path(name).parent_path().string(), result.spec, result.problems);
  } catch (const YAML::Exception& e) {
    result.problems.push_back(
        {ProblemKind::kUnreadable, {e.mark.line + 1, e.mark.column + 1}, std::string("cannot read: ") + e.msg, {}});
  }
  flatten(root, "", result.spec.fingerprint);
  for (const CaseTool& t : result.spec.tools)
    if (!t.file.empty())
      result.spec.fingerprint.emplace_back("tools[" + t.name + "] file " + t.file, file_checksum(t.file));
  check_solver_rules(result.spec, result.problems);
  // Conditions are discretised only for a case that read cleanly (valid plies).
  if (result.ok()) check_boundary_conditions(result.spec, result.problems);
  // The model itself: held plies, sane geometry, a size the machine can solve.
  if (result.ok()) check_model(result.spec, result.problems, machine_memory_bytes());
  std::stable_sort(result.problems.begin(), result.problems.end(), [](const CaseProblem& a, const CaseProblem& b) {
    return std::tie(a.place.line, a.place.column) < std::tie(b.place.line, b.place.column);
  });
  return result;
}

CaseCheck check_case_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    CaseCheck c;
    c.spec.file = path;
    c.problems.push_back({ProblemKind::kUnreadable, {}, "cannot open case file", {}});
    return c;
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return check_case_text(ss.str(), path);
}

bool restart_may_change(const std::string& key) {
  static const std::set<std::string> solver = {"max_iterations", "tolerance", "min_increment", "line_search",
                                               "predictor",      "linear",    "branch_switch"};
  const std::string prefix = "solver.";
  if (key.compare(0, prefix.size(), prefix) != 0) return false;
  const std::string rest = key.substr(prefix.size());
  if (rest == "stabilise.warn_ratio") return true;
  return solver.count(rest.substr(0, rest.find('.'))) > 0;
}

FormingCase load_case(const std::string& path) {
  CaseCheck c = check_case_file(path);
  if (!c.ok()) {
    std::string msg = c.located(0);
    if (c.problems.size() > 1)
      msg += " (and " + std::to_string(c.problems.size() - 1) + " more problems; run 'simform check " + path +
             "' to list them)";
    throw InputError(msg);
  }
  return c.spec;
}

}  // namespace sf::forming
