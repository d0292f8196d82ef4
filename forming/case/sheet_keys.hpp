#pragma once
// The keys a sheet of the case file shares wherever it is given: a ply (`plies:`), a
// laminate (`laminates:`, its plies' common keys) and a pair of diaphragms
// (`diaphragms:`), read by one function each so that the three read them alike and
// report a problem in the same words, with its line and column. Internal to
// forming/case.
#include <string>

#include "forming/case/schema.hpp"
#include "forming/case/yaml_reader.hpp"

namespace sf::forming::sheet_keys {

// Required `size: [Lx, Ly]` (mm, positive) of `parent` into sheet.length_x/_y.
bool read_size(case_yaml::Reader& r, const YAML::Node& parent, const std::string& what, CasePly& sheet);
// Required `elements: [n1, n2]` (bricks along x and y, 1 .. 1000) into sheet.n1/n2.
bool read_elements(case_yaml::Reader& r, const YAML::Node& parent, const std::string& what, CasePly& sheet);
// `key` (thickness or ply_thickness, mm, positive) into `thickness`; a missing key is a
// problem only when `required`.
bool read_thickness(case_yaml::Reader& r, const YAML::Node& parent, const std::string& key, const std::string& what,
                    bool required, double& thickness);
// Optional `plane_strain: true|false` into sheet.plane_strain.
bool read_plane_strain(case_yaml::Reader& r, const YAML::Node& parent, const std::string& what, CasePly& sheet);
// `material: NAME` of a material defined under `materials:` into sheet.material and
// sheet.material_index; a missing key is a problem only when `required`.
bool read_material(case_yaml::Reader& r, const YAML::Node& parent, const std::string& what, bool required,
                   const FormingCase& spec, CasePly& sheet);

}  // namespace sf::forming::sheet_keys
