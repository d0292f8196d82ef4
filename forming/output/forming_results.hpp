#pragma once
// The forming results of a run's final state, beside the frames (docs/forming.md
// "Forming results"):
//
//   summary.json "forming"  per ply: fibre stretch (min, max), fibre angle change,
//                           ply and trellis shear angle (max |.|, degrees), thickness
//                           (min, max, mm), wrinkling indicator (amplitude, rms,
//                           wavelength, smoothing radius, mm); the partner ply used for
//                           the trellis angle; per tool the peak press force (N)
//   profiles.csv            line profiles from the part centre along 0, 45 and 90
//                           degrees (from x towards y), every ply, at mid-thickness
//   tool_force.csv          press force against stroke of every tool (or of the tool
//                           edge without tools), one row per converged step
//
// The part centre is the centre of the plies' reference plan box, moved onto the
// symmetry planes x0 / y0 of the case when it has them (a quarter model's centre is its
// symmetry corner).
#include <string>

#include <nlohmann/json.hpp>

#include "common/core/types.hpp"
#include "forming/case/schema.hpp"
#include "forming/model/model.hpp"

namespace sf::forming {

// The "forming" block of summary.json at positions x; `samples`: columns per brick side.
nlohmann::json forming_summary(const FormingCase& spec, const Model& model, const VecX& x, int samples);

// The part centre (plan, reference, mm) and the profiles CSV text (header
// direction_deg,ply,s_mm,X_mm,Y_mm,x_mm,y_mm,z_mm,draw_in_mm,thickness_mm,
// trellis_shear_deg,ply_shear_deg,fibre_angle_change_deg,fibre_stretch).
// draw_in = s - (x - c).d in plan: how far the material point moved toward the centre
// along the line (positive: drawn in).
Vec3 part_centre(const FormingCase& spec, const Model& model);
std::string profiles_csv(const FormingCase& spec, const Model& model, const VecX& x);

// tool_force.csv from the text of history.csv (`name` for messages). Per tool T (columns
// T_ux.. T_fz of history.csv) the stroke direction d is its final displacement's
// direction: T_stroke_mm = u.d, T_force_N = -f.d (the force the press must push with,
// positive when the plies resist the stroke), then its components T_fx_N.. T_fz_N. Without
// tools the same for the tool edge (tool_u*, tool_f*: the reaction on the edge, so
// force = f.d). Columns step, time_s (load factor x process time), load_factor first.
std::string tool_force_csv(const std::string& history_text, const std::string& name, double process_time);

}  // namespace sf::forming
