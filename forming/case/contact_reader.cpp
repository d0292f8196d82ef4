#include "forming/case/contact_reader.hpp"

#include <cctype>
#include <filesystem>
#include <memory>
#include <utility>

#include "common/core/error.hpp"
#include "common/io/stl.hpp"
#include "forming/case/sheet_keys.hpp"
#include "forming/contact/tool_shape.hpp"

namespace sf::forming {

using case_yaml::describe;
using case_yaml::pair_of;
using case_yaml::place_of;
using case_yaml::ramp_of;
using case_yaml::Reader;
using case_yaml::vector3;

namespace {

// The place of character `offset` of a scalar's text: a quoted scalar's mark is at its
// opening quote (yaml-cpp tags non-plain scalars "!").
SourcePlace place_in_scalar(const YAML::Node& n, std::size_t offset) {
  SourcePlace p = place_of(n);
  if (p.line == 0) return p;
  p.column += static_cast<int>(offset) + (n.Tag() == "!" ? 1 : 0);
  return p;
}

int find_tool(const FormingCase& spec, const std::string& name) {
  for (std::size_t i = 0; i < spec.tools.size(); ++i)
    if (spec.tools[i].name == name) return static_cast<int>(i);
  return -1;
}

int find_material(const FormingCase& spec, const std::string& name) {
  for (std::size_t i = 0; i < spec.materials.size(); ++i)
    if (spec.materials[i].name == name) return static_cast<int>(i);
  return -1;
}

const std::vector<std::string> kLawKeys = {"stiffness",  "tolerance", "viscous",  "coulomb", "stick_velocity",
                                           "engage_gap", "points",    "two_pass", "band",    "tail",
                                           "tail_reach", "stick_slip"};

// The contact law keys of mapping n (those present in kLawKeys); false on a problem.
bool read_law(Reader& r, const YAML::Node& n, const std::string& what, CaseContactLaw& law) {
  bool ok = true;
  ok = r.required_key(n, "stiffness", what, law.normal.stiffness, [&](const YAML::Node& s) {
    return r.positive(s, what + " stiffness", "S_n, N/mm^3");
  }) && ok;
  if (n["tolerance"].IsDefined()) {
    if (const auto v =
            r.positive(n["tolerance"], what + " tolerance", "largest penetration, mm; augmented Lagrangian")) {
      law.normal.augmented = true;
      law.normal.tolerance = *v;
    } else
      ok = false;
  }
  const auto nonneg = [&](const char* key, const std::string& unit, double& out) {
    ok = r.optional_key(n, key, out, [&](const YAML::Node& v) { return r.non_negative(v, what + " " + key, unit); }) &&
         ok;
  };
  nonneg("viscous", "c_f, N s/mm^3", law.friction.viscous);
  nonneg("coulomb", "mu", law.friction.coulomb);
  nonneg("engage_gap", "mm", law.friction.engage_gap);
  nonneg("tail", "S_t, N/mm^3; the normal law's tie about the band's open end", law.normal.tail);
  nonneg("tail_reach", "mm; 0 = a linear tail", law.normal.tail_reach);
  if (law.normal.tail > 0.0 && law.normal.augmented) {
    r.problem(ProblemKind::kUnsupported, n["tail"], what + ": tail cannot be combined with tolerance (the augmented Lagrangian)");
    ok = false;
  }
  if (n["stick_velocity"].IsDefined()) {
    if (const auto v = r.positive(n["stick_velocity"], what + " stick_velocity", "mm/s"))
      law.friction.stick_velocity = *v;
    else
      ok = false;
  }
  if (n["stick_slip"].IsDefined()) {
    if (const auto v = r.positive(n["stick_slip"], what + " stick_slip", "mm of elastic slip before sliding"))
      law.friction.stick_slip = *v;
    else
      ok = false;
    if (n["stick_velocity"].IsDefined()) {
      r.problem(ProblemKind::kConflict, n["stick_slip"],
                what + ": give stick_slip (slip distance, mm) or stick_velocity (mm/s), not both");
      ok = false;
    }
  }
  if (law.friction.coulomb > 0.0 && !n["stick_velocity"].IsDefined() && !n["stick_slip"].IsDefined()) {
    r.problem(ProblemKind::kMissing, n["coulomb"],
              what + ": Coulomb friction needs stick_velocity (mm/s, the slip rate below which it sticks) or "
                     "stick_slip (mm, the elastic slip before it slides)");
    ok = false;
  }
  ok = r.optional_key(n, "points", law.points, [&](const YAML::Node& v) {
    return r.integer(v, what + " points (per face direction)", 1, 12);
  }) && ok;
  ok = r.optional_key(n, "band", law.band, [&](const YAML::Node& v) { return r.positive(v, what + " band", "mm"); }) &&
       ok;
  ok = r.optional_key(n, "two_pass", law.two_pass, [&](const YAML::Node& v) {
    return r.boolean(v, what + " two_pass");
  }) && ok;
  return ok;
}

std::optional<bool> face_of(Reader& r, const YAML::Node& n, const std::string& what) {
  const auto k = r.choice(n, what, {"top", "bottom"}, "top or bottom");
  if (!k) return std::nullopt;
  return *k == 0;
}

// Explicit list of plies: [{angle, thickness, material}, ...], defaults from the laminate.
bool read_layup_list(Reader& r, const YAML::Node& l, const std::string& what, double thickness,
                     const std::string& material, const FormingCase& spec, std::vector<CasePly>& plies) {
  bool ok = true;
  for (std::size_t i = 0; i < l.size(); ++i) {
    const std::string pw = what + " layup ply " + std::to_string(i + 1);
    const YAML::Node p = l[i];
    if (!r.mapping(p, pw, {"angle", "thickness", "material"})) {
      ok = false;
      continue;
    }
    CasePly ply;
    ply.place = place_of(p);
    if (const auto a = r.number(r.required(p, "angle", pw), pw + " angle (degrees)"))
      ply.angle_deg = *a;
    else
      ok = false;
    ply.thickness = thickness;
    if (p["thickness"].IsDefined()) {
      if (const auto h = r.positive(p["thickness"], pw + " thickness", "mm"))
        ply.thickness = *h;
      else
        ok = false;
    } else if (!(thickness > 0.0)) {
      r.problem(ProblemKind::kMissing, p, pw + ": no thickness (give it here or ply_thickness for the laminate)");
      ok = false;
    }
    ply.material = material;
    ok = r.optional_key(p, "material", ply.material, [&](const YAML::Node& v) {
      return r.text(v, pw + " material");
    }) && ok;
    ply.material_index = find_material(spec, ply.material);
    if (ply.material.empty()) {
      r.problem(ProblemKind::kMissing, p, pw + ": no material (give it here or for the laminate)");
      ok = false;
    } else if (ply.material_index < 0) {
      r.problem(ProblemKind::kUnknownMaterial, p["material"].IsDefined() ? p["material"] : p,
                pw + ": unknown material '" + ply.material + "'", ply.material);
      ok = false;
    }
    plies.push_back(ply);
  }
  return ok;
}

// The layup string "[0,90]s" of laminate `what`: one ply per angle, every ply of the
// laminate's ply_thickness and material (`base`).
bool read_layup_string(Reader& r, const YAML::Node& n, const YAML::Node& l, const std::string& what,
                       const CasePly& base, std::vector<CasePly>& plies) {
  std::string error;
  std::size_t offset = 0;
  const auto angles = parse_layup(l.Scalar(), error, offset);
  if (!angles) {
    r.problem(ProblemKind::kWrongType, place_in_scalar(l, offset), what + " layup '" + l.Scalar() + "': " + error);
    return false;
  }
  bool ok = true;
  if (!(base.thickness > 0.0)) {
    r.problem(ProblemKind::kMissing, n, what + ": a layup string needs ply_thickness (mm)");
    ok = false;
  }
  if (base.material.empty()) {
    r.problem(ProblemKind::kMissing, n, what + ": a layup string needs material");
    ok = false;
  }
  for (const double a : *angles) {
    CasePly p;
    p.angle_deg = a;
    p.thickness = base.thickness;
    p.material = base.material;
    p.material_index = base.material_index;
    p.place = place_of(l);
    plies.push_back(p);
  }
  return ok;
}

// The required `layup` of laminate `what`: a string or an explicit list of plies.
bool read_layup(Reader& r, const YAML::Node& n, const std::string& what, const CasePly& base, const FormingCase& spec,
                CaseLaminate& lam, std::vector<CasePly>& plies) {
  const YAML::Node l = r.required(n, "layup", what);
  if (!l.IsDefined()) return false;
  if (case_yaml::is_scalar(l)) {
    lam.layup = l.Scalar();
    return read_layup_string(r, n, l, what, base, plies);
  }
  if (case_yaml::is_sequence(l) && l.size() > 0) {
    lam.layup = "list";
    return read_layup_list(r, l, what, base.thickness, base.material, spec, plies);
  }
  r.problem(ProblemKind::kWrongType, l,
            what +
                " layup: expected a layup string such as \"[0,90]s\" or a list of {angle, thickness, material}, "
                "found " +
                describe(l));
  return false;
}

// Stacks the laminate's plies (named NAME.1 from the bottom) from the laminate's origin
// into spec.plies, with the laminate's plan size and mesh; false (with a problem) on a
// name an earlier ply uses.
bool add_laminate_plies(Reader& r, const YAML::Node& n, const std::string& what, const CasePly& base,
                        const std::vector<CasePly>& plies, CaseLaminate& lam, FormingCase& spec) {
  lam.first_ply = static_cast<int>(spec.plies.size());
  double z = base.origin.z();
  for (std::size_t k = 0; k < plies.size(); ++k) {
    CasePly p = plies[k];
    p.name = lam.name + "." + std::to_string(k + 1);
    if (spec.find_ply(p.name) >= 0) {
      r.problem(ProblemKind::kDuplicate, n["name"], what + ": ply name '" + p.name + "' used by an earlier ply");
      return false;
    }
    p.origin = Vec3(base.origin.x(), base.origin.y(), z);
    p.length_x = base.length_x;
    p.length_y = base.length_y;
    p.n1 = base.n1;
    p.n2 = base.n2;
    p.plane_strain = base.plane_strain;
    z += p.thickness;
    lam.angles.push_back(p.angle_deg);
    spec.plies.push_back(p);
  }
  return true;
}

// Contact pairs between neighbouring plies of the laminate (the lower ply's top face is
// the slave side), all with the interface law.
void add_interfaces(const CaseLaminate& lam, std::size_t n_plies, const CaseContactLaw& law, const YAML::Node& iface,
                    FormingCase& spec) {
  for (std::size_t k = 0; k + 1 < n_plies; ++k) {
    CaseContact c;
    c.ply = lam.first_ply + static_cast<int>(k);
    c.top = true;
    c.with = c.ply + 1;
    c.with_top = false;
    c.law = law;
    c.label =
        spec.plies[static_cast<std::size_t>(c.ply)].name + "/" + spec.plies[static_cast<std::size_t>(c.with)].name;
    c.place = place_of(iface);
    spec.contacts.push_back(c);
  }
}

void read_laminate(Reader& r, const YAML::Node& n, int index, FormingCase& spec) {
  std::string what = "laminate " + std::to_string(index + 1);
  if (!r.mapping(
          n, what,
          {"name", "origin", "size", "elements", "layup", "ply_thickness", "material", "interface", "plane_strain"}))
    return;
  CaseLaminate lam;
  lam.place = place_of(n);
  bool ok = true;
  if (const auto name = r.text(r.required(n, "name", what), what + " name")) {
    lam.name = *name;
    what = "laminate '" + lam.name + "'";
  } else
    ok = false;
  // The keys every ply of the laminate shares.
  CasePly base;
  ok = r.optional_key(n, "origin", base.origin, [&](const YAML::Node& o) {
    return vector3(r, o, what + " origin", "mm");
  }) && ok;
  ok = sheet_keys::read_size(r, n, what, base) && ok;
  ok = sheet_keys::read_elements(r, n, what, base) && ok;
  ok = sheet_keys::read_plane_strain(r, n, what, base) && ok;
  ok = sheet_keys::read_thickness(r, n, "ply_thickness", what, false, base.thickness) && ok;
  ok = sheet_keys::read_material(r, n, what, false, spec, base) && ok;
  std::vector<CasePly> plies;
  ok = read_layup(r, n, what, base, spec, lam, plies) && ok;
  CaseContactLaw law;
  const YAML::Node iface = n["interface"];
  if (plies.size() > 1) {
    if (!iface.IsDefined()) {
      r.problem(ProblemKind::kMissing, n,
                what + ": missing required key 'interface' (the contact law between its plies)");
      ok = false;
    } else if (r.mapping(iface, what + " interface", kLawKeys)) {
      ok = read_law(r, iface, what + " interface", law) && ok;
    } else
      ok = false;
  }
  if (!ok || !add_laminate_plies(r, n, what, base, plies, lam, spec)) return;
  add_interfaces(lam, plies.size(), law, iface, spec);
  spec.laminates.push_back(lam);
}

// The shape of a tool (exactly one shape key); nullptr with a problem recorded.
std::shared_ptr<const ToolShape> read_shape(Reader& r, const YAML::Node& n, const std::string& what,
                                            const std::string& case_dir, std::string& file) {
  static const std::vector<std::string> kShapes = {"plane", "sphere", "cylinder", "punch", "die", "mesh"};
  YAML::Node key, body;
  int found = 0;
  for (auto it = n.begin(); it != n.end(); ++it)
    if (std::find(kShapes.begin(), kShapes.end(), it->first.Scalar()) != kShapes.end()) {
      if (found++ == 0) {
        key = it->first;
        body = it->second;
      }
    }
  if (found != 1) {
    r.problem(found == 0 ? ProblemKind::kMissing : ProblemKind::kWrongType, n,
              what + ": expected exactly one shape (plane, sphere, cylinder, punch, die or mesh)");
    return nullptr;
  }
  const std::string kind = key.Scalar();
  const std::string sw = what + " " + kind;
  std::vector<std::string> keys;
  if (kind == "plane")
    keys = {"point", "normal"};
  else if (kind == "sphere")
    keys = {"centre", "radius"};
  else if (kind == "cylinder")
    keys = {"point", "axis", "radius"};
  else if (kind == "punch")
    keys = {"tip", "axis", "radius", "fillet"};
  else if (kind == "die")
    keys = {"centre", "normal", "opening_radius", "slot_half_width", "along", "edge_radius"};
  else
    keys = {"file", "scale", "offset"};
  if (!r.mapping(body, sw, keys)) return nullptr;
  const auto vec = [&](const char* k) { return vector3(r, r.required(body, k, sw), sw + " " + k, "mm"); };
  const auto len = [&](const char* k) { return r.positive(r.required(body, k, sw), sw + " " + k, "mm"); };
  try {
    if (kind == "plane") {
      const auto p = vec("point"), nn = vec("normal");
      if (p && nn) return make_plane(*p, *nn);
    } else if (kind == "sphere") {
      const auto c = vec("centre");
      const auto R = len("radius");
      if (c && R) return make_sphere(*c, *R);
    } else if (kind == "cylinder") {
      const auto p = vec("point"), a = vec("axis");
      const auto R = len("radius");
      if (p && a && R) return make_cylinder(*p, *a, *R);
    } else if (kind == "punch") {
      const auto t = vec("tip"), a = vec("axis");
      const auto R = len("radius"), f = len("fillet");
      if (t && a && R && f) return make_punch(*t, *a, *R, *f);
    } else if (kind == "die") {
      const auto c = vec("centre"), nn = vec("normal");
      const auto e = len("edge_radius");
      DieOpening o;
      bool have = true;
      if (body["opening_radius"].IsDefined() == body["slot_half_width"].IsDefined()) {
        r.problem(ProblemKind::kWrongType, body,
                  sw + ": give either opening_radius (circle) or slot_half_width and along");
        have = false;
      } else if (body["opening_radius"].IsDefined()) {
        const auto R = r.positive(body["opening_radius"], sw + " opening_radius", "mm");
        if (R)
          o.radius = *R;
        else
          have = false;
      } else {
        o.slot = true;
        const auto hw = r.positive(body["slot_half_width"], sw + " slot_half_width", "mm");
        const auto al = vector3(r, r.required(body, "along", sw), sw + " along", "a direction");
        if (hw && al) {
          o.half_width = *hw;
          o.along = *al;
        } else
          have = false;
      }
      if (c && nn && e && have) return make_die(*c, *nn, o, *e);
    } else {
      const auto f = r.text(r.required(body, "file", sw), sw + " file");
      double scale = 1.0;
      Vec3 offset = Vec3::Zero();
      if (body["scale"].IsDefined()) {
        const auto s = r.positive(body["scale"], sw + " scale", "a factor");
        if (!s) return nullptr;
        scale = *s;
      }
      if (body["offset"].IsDefined()) {
        const auto o = vector3(r, body["offset"], sw + " offset", "mm");
        if (!o) return nullptr;
        offset = *o;
      }
      if (!f) return nullptr;
      const std::filesystem::path path =
          std::filesystem::path(*f).is_absolute() ? std::filesystem::path(*f) : std::filesystem::path(case_dir) / *f;
      file = path.string();
      try {
        return make_mesh_tool(io::read_stl(file), scale, offset);
      } catch (const InputError& e) {
        r.problem(ProblemKind::kUnreadable, body["file"], sw + " file: " + e.what());
        return nullptr;
      }
    }
  } catch (const InputError& e) {
    r.problem(ProblemKind::kOutOfRange, key, what + ": " + e.what());
  }
  return nullptr;
}

std::optional<ToolMotion> read_motion(Reader& r, const YAML::Node& m, const std::string& what,
                                      const CaseSolver& solver) {
  const std::string mw = what + " motion";
  if (!r.mapping(m, mw, {"fixed", "displacement", "ramp", "duration", "velocity", "table"})) return std::nullopt;
  const int kinds =
      m["fixed"].IsDefined() + m["displacement"].IsDefined() + m["velocity"].IsDefined() + m["table"].IsDefined();
  if (kinds != 1) {
    r.problem(ProblemKind::kWrongType, m, mw + ": expected exactly one of fixed, displacement, velocity, table");
    return std::nullopt;
  }
  try {
    if (m["fixed"].IsDefined()) {
      const auto f = r.boolean(m["fixed"], mw + " fixed");
      if (f && *f) return ToolMotion::fixed();
      if (f) r.problem(ProblemKind::kOutOfRange, m["fixed"], mw + " fixed: only 'fixed: true' (or leave out motion)");
      return std::nullopt;
    }
    if (m["displacement"].IsDefined()) {
      const auto d = vector3(r, m["displacement"], mw + " displacement", "mm");
      Ramp ramp = Ramp::kLinear;
      const bool ramp_ok = ramp_of(r, m, mw, ramp);
      double duration = solver.dynamic ? solver.end_time : solver.process_time;
      if (m["duration"].IsDefined()) {
        const auto t = r.positive(m["duration"], mw + " duration", "s");
        if (!t) return std::nullopt;
        duration = *t;
      }
      if (!d || !ramp_ok) return std::nullopt;
      return ToolMotion::ramped(*d, ramp, duration);
    }
    for (const char* k : {"ramp", "duration"})
      if (m[k].IsDefined()) r.problem(ProblemKind::kUnsupported, m[k], mw + " " + k + ": only used with displacement");
    if (m["velocity"].IsDefined()) {
      const auto v = vector3(r, m["velocity"], mw + " velocity", "mm/s");
      if (!v) return std::nullopt;
      return ToolMotion::constant_velocity(*v);
    }
    const YAML::Node t = m["table"];
    if (!case_yaml::is_sequence(t) || t.size() == 0) {
      r.problem(ProblemKind::kWrongType, t,
                mw + " table: expected a list of [t, dx, dy, dz] rows, found " + describe(t));
      return std::nullopt;
    }
    std::vector<std::pair<double, Vec3>> rows;
    for (std::size_t i = 0; i < t.size(); ++i) {
      const YAML::Node row = t[i];
      if (!case_yaml::is_sequence(row) || row.size() != 4) {
        r.problem(ProblemKind::kWrongType, row,
                  mw + " table: expected a row [t (s), dx, dy, dz (mm)], found " + describe(row));
        return std::nullopt;
      }
      std::array<double, 4> v{};
      for (int c = 0; c < 4; ++c) {
        const auto x = r.number(row[c], mw + " table");
        if (!x) return std::nullopt;
        v[static_cast<std::size_t>(c)] = *x;
      }
      if (!rows.empty() && !(v[0] > rows.back().first)) {
        r.problem(ProblemKind::kOutOfRange, row[0], mw + " table: times must increase, found " + row[0].Scalar());
        return std::nullopt;
      }
      rows.emplace_back(v[0], Vec3(v[1], v[2], v[3]));
    }
    return ToolMotion::table(std::move(rows));
  } catch (const InputError& e) {
    r.problem(ProblemKind::kOutOfRange, m, mw + ": " + e.what());
  }
  return std::nullopt;
}

void read_tool(Reader& r, const YAML::Node& n, int index, const std::string& case_dir, FormingCase& spec) {
  std::string what = "tool " + std::to_string(index + 1);
  if (!r.mapping(n, what, {"name", "plane", "sphere", "cylinder", "punch", "die", "mesh", "motion"})) return;
  CaseTool t;
  t.place = place_of(n);
  bool ok = true;
  if (const auto name = r.text(r.required(n, "name", what), what + " name")) {
    t.name = *name;
    what = "tool '" + t.name + "'";
    if (find_tool(spec, t.name) >= 0 || spec.find_ply(t.name) >= 0) {
      r.problem(ProblemKind::kDuplicate, n["name"], what + ": name used by an earlier tool or ply");
      ok = false;
    }
  } else
    ok = false;
  t.tool.name = t.name;
  t.tool.shape = read_shape(r, n, what, case_dir, t.file);
  if (!t.tool.shape) ok = false;
  if (const YAML::Node m = n["motion"]; m.IsDefined()) {
    if (const auto motion = read_motion(r, m, what, spec.solver))
      t.tool.motion = *motion;
    else
      ok = false;
    if (spec.solver.arc_length > 0.0 && t.tool.motion.moves()) {
      r.problem(ProblemKind::kUnsupported, m, what + " motion: tools cannot move under control: arc_length (no time)");
      ok = false;
    }
  }
  if (ok) spec.tools.push_back(std::move(t));
}

void read_contact(Reader& r, const YAML::Node& n, int index, FormingCase& spec) {
  const std::string what = "contact " + std::to_string(index + 1);
  std::vector<std::string> keys = {"ply", "face", "tool", "with", "with_face"};
  keys.insert(keys.end(), kLawKeys.begin(), kLawKeys.end());
  if (!r.mapping(n, what, keys)) return;
  CaseContact c;
  c.place = place_of(n);
  bool ok = true;
  std::string ply_name;
  ok = case_yaml::ply_of(r, n, what, spec, ply_name, c.ply) && ok;
  ok = r.required_key(n, "face", what, c.top, [&](const YAML::Node& f) { return face_of(r, f, what + " face"); }) && ok;
  const YAML::Node tool = n["tool"], with = n["with"];
  std::string partner;
  if (tool.IsDefined() == with.IsDefined()) {
    r.problem(ProblemKind::kWrongType, n,
              what + ": expected exactly one partner: tool (a tool's name) or with (a ply's name)");
    ok = false;
  } else if (tool.IsDefined()) {
    if (const auto name = r.text(tool, what + " tool")) {
      partner = *name;
      c.tool = find_tool(spec, *name);
      if (c.tool < 0) {
        r.problem(ProblemKind::kUnknownTool, tool, what + ": unknown tool '" + *name + "' (not defined under tools)",
                  *name);
        ok = false;
      }
    } else
      ok = false;
    if (n["with_face"].IsDefined()) {
      r.problem(ProblemKind::kUnsupported, n["with_face"], what + " with_face: only used with 'with' (a ply)");
      ok = false;
    }
    if (n["two_pass"].IsDefined()) {
      r.problem(ProblemKind::kUnsupported, n["two_pass"],
                what + " two_pass: only for contact between plies (a rigid tool is checked in one pass)");
      ok = false;
    }
  } else {
    if (const auto name = r.text(with, what + " with")) {
      partner = *name;
      c.with = spec.find_ply(*name);
      if (c.with < 0) {
        r.problem(ProblemKind::kUnknownPly, with, what + ": unknown ply '" + *name + "'", *name);
        ok = false;
      } else if (c.with == c.ply) {
        r.problem(ProblemKind::kOutOfRange, with, what + ": a ply cannot be in contact with itself");
        ok = false;
      }
    } else
      ok = false;
    ok = r.required_key(n, "with_face", what, c.with_top, [&](const YAML::Node& f) {
      return face_of(r, f, what + " with_face");
    }) && ok;
  }
  ok = read_law(r, n, what, c.law) && ok;
  if (ok && spec.solver.arc_length > 0.0 && c.law.friction.active()) {
    r.problem(ProblemKind::kUnsupported, n,
              what + ": friction needs slip rates, which control: arc_length does not have");
    ok = false;
  }
  if (!ok) return;
  c.label = ply_name + "/" + partner;
  spec.contacts.push_back(c);
}

}  // namespace

std::optional<std::vector<double>> parse_layup(const std::string& text, std::string& error, std::size_t& offset) {
  std::size_t i = 0;
  const auto fail = [&](const std::string& why) -> std::optional<std::vector<double>> {
    error = why;
    offset = i;
    return std::nullopt;
  };
  const auto skip = [&] {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  };
  const auto integer = [&](int& out) {
    const std::size_t start = i;
    long v = 0;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])) && v < 100000)
      v = 10 * v + (text[i++] - '0');
    out = static_cast<int>(v);
    return i > start && v > 0;
  };
  skip();
  if (i >= text.size() || text[i] != '[') return fail("expected '[' to open the layup, e.g. [0,90]s");
  ++i;
  std::vector<double> angles;
  for (;;) {
    skip();
    const std::size_t start = i;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) ++i;
    while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.')) ++i;
    if (i == start || (i == start + 1 && (text[start] == '+' || text[start] == '-'))) {
      i = start;
      return fail("expected a ply angle (degrees)");
    }
    char* end = nullptr;
    const std::string number = text.substr(start, i - start);
    const double a = std::strtod(number.c_str(), &end);
    if (end != number.c_str() + number.size()) {
      i = start;
      return fail("expected a ply angle (degrees), found '" + number + "'");
    }
    int count = 1;
    if (i < text.size() && text[i] == '_') {
      ++i;
      if (!integer(count)) return fail("expected a positive ply count after '_'");
    }
    angles.insert(angles.end(), static_cast<std::size_t>(count), a);
    skip();
    if (i < text.size() && (text[i] == ',' || text[i] == '/')) {
      ++i;
      continue;
    }
    if (i < text.size() && text[i] == ']') {
      ++i;
      break;
    }
    return fail(i < text.size() ? std::string("expected ',', '/' or ']', found '") + text[i] + "'"
                                : "expected ']' to close the layup");
  }
  int repeat = 1;
  if (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])) && !integer(repeat))
    return fail("expected a positive repeat count");
  std::vector<double> out;
  for (int k = 0; k < repeat; ++k) out.insert(out.end(), angles.begin(), angles.end());
  if (i < text.size() && text[i] == 's') {
    ++i;
    const std::vector<double> mirrored(out.rbegin(), out.rend());
    out.insert(out.end(), mirrored.begin(), mirrored.end());
  }
  skip();
  if (i < text.size()) return fail(std::string("unexpected '") + text[i] + "' after the layup");
  if (out.size() > 200) {
    i = 0;
    return fail("more than 200 plies");
  }
  return out;
}

void read_laminates(Reader& r, const YAML::Node& n, FormingCase& spec) {
  if (!case_yaml::is_sequence(n) || n.size() == 0) {
    r.problem(ProblemKind::kWrongType, n, "laminates: expected a list (- name: ...), found " + describe(n));
    return;
  }
  for (std::size_t i = 0; i < n.size(); ++i) read_laminate(r, n[i], static_cast<int>(i), spec);
}

void read_tools(Reader& r, const YAML::Node& n, const std::string& case_dir, FormingCase& spec) {
  if (!case_yaml::is_sequence(n) || n.size() == 0) {
    r.problem(ProblemKind::kWrongType, n, "tools: expected a list (- name: ...), found " + describe(n));
    return;
  }
  for (std::size_t i = 0; i < n.size(); ++i) read_tool(r, n[i], static_cast<int>(i), case_dir, spec);
}

const std::vector<std::string>& contact_law_keys() { return kLawKeys; }

bool read_contact_law(Reader& r, const YAML::Node& n, const std::string& what, CaseContactLaw& law) {
  return read_law(r, n, what, law);
}

void read_contacts(Reader& r, const YAML::Node& n, FormingCase& spec) {
  if (!case_yaml::is_sequence(n) || n.size() == 0) {
    r.problem(ProblemKind::kWrongType, n, "contact: expected a list (- ply: ...), found " + describe(n));
    return;
  }
  for (std::size_t i = 0; i < n.size(); ++i) read_contact(r, n[i], static_cast<int>(i), spec);
}

}  // namespace sf::forming
