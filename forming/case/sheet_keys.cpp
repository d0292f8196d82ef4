#include "forming/case/sheet_keys.hpp"

namespace sf::forming::sheet_keys {

using case_yaml::pair_of;
using case_yaml::Reader;

bool read_size(Reader& r, const YAML::Node& parent, const std::string& what, CasePly& sheet) {
  const YAML::Node s = r.required(parent, "size", what);
  if (!s.IsDefined() || !pair_of(r, s, what + " size")) return false;
  const auto a = r.positive(s[0], what + " size Lx", "mm");
  const auto b = r.positive(s[1], what + " size Ly", "mm");
  if (!a || !b) return false;
  sheet.length_x = *a;
  sheet.length_y = *b;
  return true;
}

bool read_elements(Reader& r, const YAML::Node& parent, const std::string& what, CasePly& sheet) {
  const YAML::Node e = r.required(parent, "elements", what);
  if (!e.IsDefined() || !pair_of(r, e, what + " elements")) return false;
  const auto a = r.integer(e[0], what + " elements along x", 1, 1000);
  const auto b = r.integer(e[1], what + " elements along y", 1, 1000);
  if (!a || !b) return false;
  sheet.n1 = *a;
  sheet.n2 = *b;
  return true;
}

bool read_thickness(Reader& r, const YAML::Node& parent, const std::string& key, const std::string& what, bool required,
                    double& thickness) {
  const YAML::Node t = required ? r.required(parent, key, what) : parent[key];
  if (!t.IsDefined()) return !required;
  const auto h = r.positive(t, what + " " + key, "mm");
  if (!h) return false;
  thickness = *h;
  return true;
}

bool read_plane_strain(Reader& r, const YAML::Node& parent, const std::string& what, CasePly& sheet) {
  const YAML::Node ps = parent["plane_strain"];
  if (!ps.IsDefined()) return true;
  const auto v = r.boolean(ps, what + " plane_strain");
  if (!v) return false;
  sheet.plane_strain = *v;
  return true;
}

bool read_material(Reader& r, const YAML::Node& parent, const std::string& what, bool required, const FormingCase& spec,
                   CasePly& sheet) {
  const YAML::Node m = required ? r.required(parent, "material", what) : parent["material"];
  if (!m.IsDefined()) return !required;
  const auto name = r.text(m, what + " material");
  if (!name) return false;
  sheet.material = *name;
  sheet.material_index = -1;
  for (std::size_t i = 0; i < spec.materials.size(); ++i)
    if (spec.materials[i].name == *name) sheet.material_index = static_cast<int>(i);
  if (sheet.material_index < 0) {
    r.problem(ProblemKind::kUnknownMaterial, m,
              what + ": unknown material '" + *name + "' (not defined under materials)", *name);
    return false;
  }
  return true;
}

}  // namespace sf::forming::sheet_keys
