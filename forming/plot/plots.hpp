#pragma once
// `simform plot RESULTS_DIR` (and the end of `simform run` unless --no-plots): headless,
// deterministic pictures of a forming run drawn from its results folder with the shared
// renderer (common/render), and a report.html that shows them (docs/forming.md
// "Pictures and report").
//
//   plots/shape.png               the deformed plies stacked with the tools (dies solid,
//                                 tools above the plies as a wireframe), coloured by the
//                                 displacement magnitude (mm)
//   plots/fibre_stress.png        per ply, side by side in plan: the Cauchy stress along
//                                 the fibres a.sigma.a (MPa), top face
//   plots/shear_angle.png         per ply: the trellis shear angle against its partner ply
//                                 (degrees; the ply's own in-plane shear angle where the
//                                 ply has no partner)
//   plots/thickness.png           per ply: the ply thickness (mm)
//   plots/contact_pressure.png    per ply: the contact pressure on its faces (MPa; the
//                                 larger of top and bottom), with contact only
//   plots/fibres.png              fibre directions of one ply (default: the top
//                                 fibre-reinforced ply) as short line segments on it
//   plots/section.png             2-D (plane strain) cases: the front section of every
//                                 ply in its own colour with the tools' section lines;
//                                 3-D parts: the vertical section through the part's
//                                 centre at the plan angle section_angle_deg (every ply's
//                                 cut in its own colour, the tools' profiles)
//   plots/force_displacement.png  press force against stroke of every tool (tool_force.csv)
//   plots/frames/frame_NNNN.png   the forming as a frame sequence (displacement magnitude
//                                 on one colour range), and plots/forming.avi (Motion JPEG)
//                                 when OpenCV's video writer can make one
//   report.html                   the run's summary and every picture
//
// The last written frame is drawn. Errors (a folder that is not a simform results folder,
// a missing or unreadable file) throw sf::InputError naming the file.
#include <string>
#include <vector>

#include "common/render/scene.hpp"

namespace sf::forming {

struct PlotOptions {
  std::string ply;  // fibre glyph ply name; empty: the top fibre-reinforced ply
  render::ImageSize size{1200, 900};
  int frames = 10;                         // frames in the sequence (0: none); evenly spread, last included
  render::ImageSize frame_size{800, 600};  // of the frames of the sequence
  bool animation = true;                   // forming.avi when possible
  double section_angle_deg = 0.0;          // 3-D parts: plan angle of the vertical section plane through the centre
  bool quiet = false;
};

struct PlotReport {
  std::vector<std::string> pictures;  // relative to the results folder, in report order
  std::string animation;              // relative path, or empty (with the reason in `notes`)
  std::vector<std::string> notes;
};

PlotReport plot_results(const std::string& results_dir, const PlotOptions& options);

}  // namespace sf::forming
