#pragma once
// The `diaphragms:` section of a case file (double-diaphragm forming; docs/forming.md
// "Diaphragms"), read by forming/case/reader.cpp after `tools` and before `contact`.
// It sets up, from one mapping, what a double-diaphragm rig is:
//
//   diaphragms:
//     name: dd                       # plies dd.lower and dd.upper
//     laminate: lam                  # the laminate held between them
//     frame: {origin: [x0, y0], size: [Lx, Ly]}   # mm; inside of the clamping frame;
//                                    # origin default: the frame centred on the laminate
//     elements: [nx, ny]             # per diaphragm
//     thickness: 1.5                 # mm
//     material: rubber               # an isotropic law (neo_hookean or mooney_rivlin)
//     symmetry: [x0, y0]             # frame edges on symmetry planes (quarter / half models);
//                                    # the other edges are clamped (plane strain: x0, x1 only)
//     pressure: {value: 0.1, face: top, ramp: linear}   # forming pressure, MPa, on the
//                                    # upper diaphragm's top (or the lower one's bottom)
//                                    # or {table: [[t, p], ...], face: top} (s, MPa)
//     vacuum: {pressure: 0.09, ramp: linear, hold: friction}   # MPa on both outer
//                                    # faces; hold: tie ties the laminate's outer faces
//                                    # to the sheets (forming/model/tied_faces.hpp)
//                                    # or {table: [[t, p], ...]} (s, MPa)
//     contact: {stiffness: 50, coulomb: 0.5, stick_velocity: 0.01}  # diaphragm-laminate
//                                    # and diaphragm-diaphragm law (the vacuum's grip)
//     tools: [{tool: die, stiffness: 50}]   # lower diaphragm (bottom face) against tools;
//                                    # face: top puts the upper diaphragm against it
//
// The section becomes two plies (lower: top face at the laminate's bottom; upper: bottom
// face at the laminate's top), clamps and symmetry conditions on the frame edges, the
// pressures as follower loads, and contact pairs laminate-diaphragm (the laminate's
// outer plies are the slave side), upper-lower diaphragm (outside the laminate) and
// diaphragm-tool. Every problem is reported with its line and column.
#include "forming/case/schema.hpp"
#include "forming/case/yaml_reader.hpp"

namespace sf::forming {

void read_diaphragms(case_yaml::Reader& r, const YAML::Node& n, FormingCase& spec);

}  // namespace sf::forming
