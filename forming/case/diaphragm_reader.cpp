#include "forming/case/diaphragm_reader.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "forming/case/contact_reader.hpp"
#include "forming/case/sheet_keys.hpp"

namespace sf::forming {

using case_yaml::describe;
using case_yaml::pair_of;
using case_yaml::place_of;
using case_yaml::Reader;

namespace {

// Slack (mm, relative to the frame size) when checking that the frame holds the laminate.
constexpr double kFrameSlack = 1e-9;

std::optional<PlySide> side_of(const std::string& s) {
  if (s == "x0") return PlySide::kX0;
  if (s == "x1") return PlySide::kX1;
  if (s == "y0") return PlySide::kY0;
  if (s == "y1") return PlySide::kY1;
  return std::nullopt;
}

// `table: [[t, p], ...]` (s, MPa) of pressure entry `p` into load.table (and load.value =
// the largest p, for the summary): t from 0, increasing; p >= 0. False on a problem.
bool read_pressure_table(Reader& r, const YAML::Node& t, const std::string& what, CaseLoad& load) {
  const std::string tw = what + " table";
  if (!case_yaml::is_sequence(t) || t.size() < 2) {
    r.problem(ProblemKind::kWrongType, t,
              tw + ": expected a list of at least two [t, p] pairs (s, MPa), e.g. [[0, 0], [0.5, 0.3]], found " +
                  describe(t));
    return false;
  }
  bool ok = true;
  for (std::size_t k = 0; k < t.size(); ++k) {
    const std::string ew = tw + " entry " + std::to_string(k + 1);
    if (!pair_of(r, t[k], ew + " [t, p]")) {
      ok = false;
      continue;
    }
    const auto time = r.number(t[k][0], ew + " t (s)");
    const auto p = r.number(t[k][1], ew + " p (MPa)");
    if (!time || !p) {
      ok = false;
      continue;
    }
    if (k == 0 && *time != 0.0) {
      r.problem(ProblemKind::kOutOfRange, t[k][0],
                ew + " t: expected the table to start at t = 0 s, found " + t[k][0].Scalar());
      ok = false;
    } else if (k > 0 && !load.table.empty() && !(*time > load.table.back()[0])) {
      r.problem(ProblemKind::kOutOfRange, t[k][0],
                ew + " t: expected times in increasing order (after " + t[k - 1][0].Scalar() + " s), found " +
                    t[k][0].Scalar());
      ok = false;
    }
    if (*p < 0.0) {
      r.problem(ProblemKind::kOutOfRange, t[k][1],
                ew + " p: expected a pressure >= 0 (MPa), found " + t[k][1].Scalar());
      ok = false;
    }
    load.table.push_back({*time, *p});
    load.value = std::max(load.value, *p);
  }
  if (!ok) load.table.clear();
  return ok;
}

// The pressure mapping {value | table, face?, ramp?} of `key`; false on a problem.
bool read_pressure_entry(Reader& r, const YAML::Node& p, const std::string& what, bool with_face, CaseLoad& load) {
  std::vector<std::string> keys = {"value", "table", "ramp"};
  if (with_face) keys.push_back("face");
  if (!r.mapping(p, what, keys)) return false;
  bool ok = true;
  if (p["table"].IsDefined()) {
    if (p["value"].IsDefined() || p["ramp"].IsDefined()) {
      r.problem(ProblemKind::kWrongType, p["table"],
                what + ": give either value (MPa, with its ramp) or a time table, not both");
      ok = false;
    } else
      ok = read_pressure_table(r, p["table"], what, load);
  } else {
    ok = r.required_key(p, "value", what, load.value,
                        [&](const YAML::Node& v) { return r.positive(v, what + " value", "MPa"); });
  }
  if (with_face && p["face"].IsDefined()) {
    if (const auto k = r.choice(p["face"], what + " face", {"top", "bottom"},
                                "top (on the upper diaphragm, pushing down) or bottom (on the lower diaphragm, "
                                "pushing up)"))
      load.top = *k == 0;
    else
      ok = false;
  }
  if (!case_yaml::ramp_of(r, p, what, load.ramp)) ok = false;
  load.kind = CaseLoad::Kind::kPressure;
  load.follower = true;
  load.place = place_of(p);
  return ok;
}

}  // namespace

void read_diaphragms(Reader& r, const YAML::Node& n, FormingCase& spec) {
  std::string what = "diaphragms";
  if (!r.mapping(n, what,
                 {"name", "laminate", "frame", "elements", "thickness", "material", "symmetry", "pressure", "vacuum",
                  "contact", "tools"}))
    return;
  bool ok = true;
  CaseDiaphragms d;
  d.place = place_of(n);
  if (const auto name = r.text(r.required(n, "name", what), what + " name")) {
    d.name = *name;
    what = "diaphragms '" + d.name + "'";
  } else
    ok = false;
  // The laminate.
  const CaseLaminate* lam = nullptr;
  if (const YAML::Node l = r.required(n, "laminate", what); l.IsDefined()) {
    if (const auto t = r.text(l, what + " laminate")) {
      const auto it = std::find_if(spec.laminates.begin(), spec.laminates.end(),
                                   [&](const CaseLaminate& c) { return c.name == *t; });
      if (it == spec.laminates.end()) {
        r.problem(ProblemKind::kUnknownPly, l,
                  what + " laminate: unknown laminate '" + *t + "' (not defined under laminates)");
        ok = false;
      } else
        lam = &*it;
    } else
      ok = false;
  } else
    ok = false;
  // Geometry and law of the sheets (the keys a ply has).
  CasePly sheet;
  ok = sheet_keys::read_elements(r, n, what, sheet) && ok;
  ok = sheet_keys::read_thickness(r, n, "thickness", what, true, sheet.thickness) && ok;
  if (sheet_keys::read_material(r, n, what, true, spec, sheet)) {
    if (spec.materials[static_cast<std::size_t>(sheet.material_index)].kind ==
        CaseMaterial::Kind::kTransverselyIsotropic) {
      r.problem(ProblemKind::kOutOfRange, n["material"],
                what +
                    " material: a diaphragm is an isotropic rubber sheet; expected a neo_hookean or "
                    "mooney_rivlin material, found '" +
                    sheet.material + "' (transversely_isotropic)");
      ok = false;
    }
  } else
    ok = false;
  // Frame.
  double fx0 = 0.0, fy0 = 0.0, flx = 0.0, fly = 0.0;
  bool origin_given = false;
  const YAML::Node frame = r.required(n, "frame", what);
  if (frame.IsDefined() && r.mapping(frame, what + " frame", {"origin", "size"})) {
    CasePly inside;  // the frame's inside, read like a ply's size
    if (sheet_keys::read_size(r, frame, what + " frame", inside)) {
      flx = inside.length_x;
      fly = inside.length_y;
    } else
      ok = false;
    if (const YAML::Node o = frame["origin"]; o.IsDefined()) {
      if (pair_of(r, o, what + " frame origin")) {
        const auto a = r.number(o[0], what + " frame origin x");
        const auto b = r.number(o[1], what + " frame origin y");
        if (a && b) {
          fx0 = *a;
          fy0 = *b;
          origin_given = true;
        } else
          ok = false;
      } else
        ok = false;
    }
  } else
    ok = false;
  // Symmetry edges.
  std::vector<PlySide> symmetric;
  if (const YAML::Node s = n["symmetry"]; s.IsDefined()) {
    if (!case_yaml::is_sequence(s)) {
      r.problem(
          ProblemKind::kWrongType, s,
          what + " symmetry: expected a list of frame edges on symmetry planes, e.g. [x0, y0], found " + describe(s));
      ok = false;
    } else {
      for (const YAML::Node& e : s) {
        const auto side = case_yaml::is_scalar(e) ? side_of(e.Scalar()) : std::nullopt;
        if (!side) {
          r.problem(ProblemKind::kWrongType, e, what + " symmetry: expected x0, x1, y0 or y1, found " + describe(e));
          ok = false;
        } else
          symmetric.push_back(*side);
      }
    }
  }
  // Loads.
  CaseLoad forming;
  bool has_forming = false;
  if (const YAML::Node p = n["pressure"]; p.IsDefined()) {
    has_forming = read_pressure_entry(r, p, what + " pressure", true, forming);
    ok = has_forming && ok;
  }
  CaseLoad vacuum;
  vacuum.ramp = Ramp::kLinear;  // constant: the first step must carry it all (cut-backs cannot reduce it)
  bool has_vacuum = false;
  bool tie = false;  // vacuum hold: tie
  if (const YAML::Node v = n["vacuum"]; v.IsDefined()) {
    if (case_yaml::is_map(v) && v["table"].IsDefined() && !v["pressure"].IsDefined()) {
      // vacuum: {table: [[0, 0], [0.1, 0.09]]}
      if (r.mapping(v, what + " vacuum", {"table", "hold"}))
        has_vacuum = read_pressure_table(r, v["table"], what + " vacuum", vacuum);
    } else if (case_yaml::is_map(v) && v["pressure"].IsDefined()) {
      const YAML::Node p = v["pressure"];
      // vacuum: {pressure: 0.09, ramp: constant, hold: tie}
      if (r.mapping(v, what + " vacuum", {"pressure", "ramp", "hold"})) {
        if (const auto x = r.positive(p, what + " vacuum pressure", "MPa, the atmosphere over the vacuum")) {
          vacuum.value = *x;
          has_vacuum = case_yaml::ramp_of(r, v, what + " vacuum", vacuum.ramp);
        }
      }
    } else {
      r.problem(ProblemKind::kWrongType, v,
                what +
                    " vacuum: expected {pressure: MPa (e.g. 0.09), ramp: constant|linear|smooth} or {table: [[t, p], "
                    "...]} (s, MPa), found " +
                    describe(v));
    }
    vacuum.kind = CaseLoad::Kind::kPressure;
    vacuum.follower = true;
    vacuum.place = place_of(v);
    if (case_yaml::is_map(v) && v["hold"].IsDefined()) {
      if (const auto k = r.choice(v["hold"], what + " vacuum hold", {"friction", "tie"},
                                  "friction (the laminate held by the contact law's friction) or tie (its outer "
                                  "faces tied to the diaphragms)"))
        tie = *k == 1;
      else
        ok = false;
    }
    ok = has_vacuum && ok;
  }
  if (!has_forming && !n["pressure"].IsDefined() && !n["tools"].IsDefined()) {
    r.problem(ProblemKind::kMissing, n, what + ": nothing forms the diaphragms: give pressure or tools");
    ok = false;
  }
  // Contact laws.
  CaseContactLaw grip;
  if (const YAML::Node c = r.required(n, "contact", what); r.mapping(c, what + " contact", contact_law_keys()))
    ok = read_contact_law(r, c, what + " contact", grip) && ok;
  else
    ok = false;
  struct ToolPair {
    int tool = -1;
    bool top = false;
    CaseContactLaw law;
    std::string name;
    SourcePlace place;
  };
  std::vector<ToolPair> tool_pairs;
  if (const YAML::Node ts = n["tools"]; ts.IsDefined()) {
    if (!case_yaml::is_sequence(ts) || ts.size() == 0) {
      r.problem(
          ProblemKind::kWrongType, ts,
          what + " tools: expected a list ({tool: NAME, stiffness: N/mm^3, face: bottom|top}), found " + describe(ts));
      ok = false;
    } else {
      for (std::size_t i = 0; i < ts.size(); ++i) {
        const std::string tw = what + " tools " + std::to_string(i + 1);
        std::vector<std::string> keys = {"tool", "face"};
        for (const std::string& k : contact_law_keys())
          if (k != "two_pass") keys.push_back(k);
        if (!r.mapping(ts[i], tw, keys)) {
          ok = false;
          continue;
        }
        ToolPair tp;
        tp.place = place_of(ts[i]);
        if (const auto t = r.text(r.required(ts[i], "tool", tw), tw + " tool")) {
          tp.name = *t;
          for (std::size_t k = 0; k < spec.tools.size(); ++k)
            if (spec.tools[k].name == *t) tp.tool = static_cast<int>(k);
          if (tp.tool < 0) {
            r.problem(ProblemKind::kUnknownTool, ts[i]["tool"],
                      tw + ": unknown tool '" + *t + "' (not defined under tools)", *t);
            ok = false;
          }
        } else
          ok = false;
        if (const YAML::Node f = ts[i]["face"]; f.IsDefined()) {
          if (const auto k =
                  r.choice(f, tw + " face", {"bottom", "top"}, "bottom (the lower diaphragm) or top (the upper one)"))
            tp.top = *k == 1;
          else
            ok = false;
        }
        ok = read_contact_law(r, ts[i], tw, tp.law) && ok;
        tool_pairs.push_back(tp);
      }
    }
  }
  if (!ok || lam == nullptr) return;

  // The laminate's plies and extent.
  const std::size_t first = static_cast<std::size_t>(lam->first_ply);
  const std::size_t last = first + lam->angles.size() - 1;
  const CasePly& bottom = spec.plies[first];
  const CasePly& top = spec.plies[last];
  const double lam_top = top.origin.z() + top.thickness;
  if (!origin_given) {
    fx0 = bottom.origin.x() + 0.5 * (bottom.length_x - flx);
    fy0 = bottom.origin.y() + 0.5 * (bottom.length_y - fly);
  }
  const double slack = kFrameSlack * std::max(flx, fly);
  if (bottom.origin.x() < fx0 - slack || bottom.origin.y() < fy0 - slack ||
      bottom.origin.x() + bottom.length_x > fx0 + flx + slack ||
      bottom.origin.y() + bottom.length_y > fy0 + fly + slack) {
    r.problem(ProblemKind::kOutOfRange, frame,
              what + " frame: the laminate '" + lam->name + "' must lie inside the frame (x " + std::to_string(fx0) +
                  " .. " + std::to_string(fx0 + flx) + ", y " + std::to_string(fy0) + " .. " +
                  std::to_string(fy0 + fly) + " mm)");
    return;
  }
  sheet.plane_strain = bottom.plane_strain;
  if (sheet.plane_strain && sheet.n2 != 1) {
    r.problem(ProblemKind::kOutOfRange, n["elements"],
              what + " elements: the laminate is plane strain; mesh the width with one element ([n, 1])");
    return;
  }
  for (const std::string& suffix : {std::string("lower"), std::string("upper")}) {
    if (spec.find_ply(d.name + "." + suffix) >= 0) {
      r.problem(ProblemKind::kDuplicate, n["name"],
                what + ": ply name '" + d.name + "." + suffix + "' used by an earlier ply");
      return;
    }
  }
  sheet.length_x = flx;
  sheet.length_y = fly;
  sheet.angle_deg = 0.0;
  sheet.place = d.place;
  CasePly lower = sheet, upper = sheet;
  lower.name = d.name + ".lower";
  lower.origin = Vec3(fx0, fy0, bottom.origin.z() - sheet.thickness);
  upper.name = d.name + ".upper";
  upper.origin = Vec3(fx0, fy0, lam_top);
  d.lower = static_cast<int>(spec.plies.size());
  spec.plies.push_back(lower);
  d.upper = static_cast<int>(spec.plies.size());
  spec.plies.push_back(upper);
  d.laminate = lam->name;

  // The frame: clamps, or symmetry on the listed edges.
  std::vector<PlySide> sides = {PlySide::kX0, PlySide::kX1};
  if (!sheet.plane_strain) sides.insert(sides.end(), {PlySide::kY0, PlySide::kY1});
  for (const int ply : {d.lower, d.upper}) {
    for (const PlySide side : sides) {
      CaseBoundary bc;
      bc.kind = std::find(symmetric.begin(), symmetric.end(), side) != symmetric.end() ? CaseBoundary::Kind::kSymmetry
                                                                                       : CaseBoundary::Kind::kClamp;
      bc.ply = spec.plies[static_cast<std::size_t>(ply)].name;
      bc.ply_index = ply;
      bc.side = side;
      bc.place = frame.IsDefined() ? place_of(frame) : d.place;
      spec.boundaries.push_back(bc);
    }
  }
  // Loads: forming pressure on one outer face, vacuum on both.
  if (has_forming) {
    forming.ply_index = forming.top ? d.upper : d.lower;
    forming.ply = spec.plies[static_cast<std::size_t>(forming.ply_index)].name;
    spec.loads.push_back(forming);
  }
  if (has_vacuum) {
    for (const bool on_top : {true, false}) {
      CaseLoad v = vacuum;
      v.top = on_top;
      v.ply_index = on_top ? d.upper : d.lower;
      v.ply = spec.plies[static_cast<std::size_t>(v.ply_index)].name;
      spec.loads.push_back(v);
    }
  }
  // Contact: the laminate's outer plies (slave) on the diaphragms, the upper diaphragm on
  // the lower one outside the laminate, and the diaphragms on the tools.
  const auto add = [&](int ply, bool ply_top, int with, bool with_top, const CaseContactLaw& law, SourcePlace at) {
    CaseContact c;
    c.ply = ply;
    c.top = ply_top;
    c.with = with;
    c.with_top = with_top;
    c.law = law;
    c.label = spec.plies[static_cast<std::size_t>(ply)].name + "/" + spec.plies[static_cast<std::size_t>(with)].name;
    c.place = at;
    spec.contacts.push_back(c);
  };
  const SourcePlace grip_at = place_of(n["contact"]);
  add(static_cast<int>(first), false, d.lower, true, grip, grip_at);
  add(static_cast<int>(last), true, d.upper, false, grip, grip_at);
  if (tie) {  // the vacuum's grip as a tie of the laminate's outer faces to the sheets
    spec.contacts[spec.contacts.size() - 2].tie = true;
    spec.contacts[spec.contacts.size() - 1].tie = true;
  }
  add(d.upper, false, d.lower, true, grip, grip_at);
  for (const ToolPair& tp : tool_pairs) {
    CaseContact c;
    c.ply = tp.top ? d.upper : d.lower;
    c.top = tp.top;
    c.tool = tp.tool;
    c.law = tp.law;
    c.label = spec.plies[static_cast<std::size_t>(c.ply)].name + "/" + tp.name;
    c.place = tp.place;
    spec.contacts.push_back(c);
  }
  spec.diaphragms.push_back(d);
}

}  // namespace sf::forming
