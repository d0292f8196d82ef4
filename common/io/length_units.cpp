#include "common/io/length_units.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <utility>

namespace sf::io {

namespace {

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t");
  return s.substr(first, last - first + 1);
}

}  // namespace

NameAndUnit split_unit(std::string_view name) {
  NameAndUnit out;
  const std::string_view t = trim(name);
  if (t.size() >= 2 && t.back() == ']') {
    const auto open = t.rfind('[');
    if (open != std::string_view::npos && open > 0) {
      out.base = std::string(trim(t.substr(0, open)));
      out.unit = std::string(trim(t.substr(open + 1, t.size() - open - 2)));
      out.has_unit = !out.base.empty();
      if (out.has_unit) return out;
    }
  }
  out = NameAndUnit{std::string(t), "", false};
  return out;
}

std::optional<double> millimetres_per(std::string_view unit) {
  static constexpr std::array<std::pair<std::string_view, double>, 9> kUnits = {{
      {"mm", 1.0},
      {"cm", 10.0},
      {"m", 1000.0},
      {"\xC2\xB5m", 1e-3},  // µm, MICRO SIGN
      {"\xCE\xBCm", 1e-3},  // μm, GREEK SMALL LETTER MU
      {"um", 1e-3},
      {"nm", 1e-6},
      {"in", 25.4},
      {"inch", 25.4},
  }};
  const std::string_view u = trim(unit);
  for (const auto& [name, mm] : kUnits)
    if (u == name) return mm;
  return std::nullopt;
}

bool is_pixel_unit(std::string_view unit) {
  std::string u(trim(unit));
  std::transform(u.begin(), u.end(), u.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return u == "px" || u == "pixel" || u == "pixels";
}

std::string known_length_units() { return "mm, cm, m, \xC2\xB5m, nm, in"; }

}  // namespace sf::io
