#pragma once
// The laminate, tool and contact sections of a case file (docs/forming.md "Laminates,
// tools and contact"), read by forming/case/reader.cpp with the same Reader, so every
// problem has its line and column:
//
//   read_laminates  each laminate becomes plies "<name>.1" (bottom) .. "<name>.n" in
//                   spec.plies, stacked through the thickness, and contact pairs
//                   between neighbours in spec.contacts; the layup is a string
//                   ("[0,90]s", "[0_4]", "[+45,-45]s", "[0/90]2s") or an explicit list
//                   of {angle, thickness, material};
//   read_tools      rigid tools: one shape (plane, sphere, cylinder, punch, die, mesh
//                   from an STL file relative to the case file) and a motion;
//   read_contacts   contact pairs naming plies and tools that exist, with their laws.
//
// parse_layup() is the layup grammar, apart so it can be tested alone.
#include <optional>
#include <string>
#include <vector>

#include "forming/case/schema.hpp"
#include "forming/case/yaml_reader.hpp"

namespace sf::forming {

// The ply angles of a layup string, bottom first:
//   layup  = "[" items "]" [repeat] ["s"]      repeat: a positive integer
//   items  = item {("," | "/") item}
//   item   = angle ["_" count]                 angle: a signed number (degrees)
// "s" mirrors the whole sequence ([0,90]s = 0, 90, 90, 0); repeat repeats it before
// mirroring. On failure returns nothing and sets `error` and the 0-based offset in the
// string where it was found.
std::optional<std::vector<double>> parse_layup(const std::string& text, std::string& error, std::size_t& offset);

void read_laminates(case_yaml::Reader& r, const YAML::Node& n, FormingCase& spec);
// `case_dir`: the folder STL paths are relative to. Tool motions need the solver
// section read first (ramps default to the process or end time).
void read_tools(case_yaml::Reader& r, const YAML::Node& n, const std::string& case_dir, FormingCase& spec);
void read_contacts(case_yaml::Reader& r, const YAML::Node& n, FormingCase& spec);

// The contact law keys (stiffness, tolerance, viscous, coulomb, stick_velocity,
// engage_gap, points, two_pass, band) and their reader, for other sections that set up
// contact pairs (forming/case/diaphragm_reader.cpp): reads those of mapping n present,
// stiffness required; false (with problems recorded) on a bad value.
const std::vector<std::string>& contact_law_keys();
bool read_contact_law(case_yaml::Reader& r, const YAML::Node& n, const std::string& what, CaseContactLaw& law);

}  // namespace sf::forming
