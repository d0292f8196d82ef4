#include "gsa/strain_measure.hpp"

#include <cmath>
#include <limits>

namespace sf::gsa {

std::string measure_name(StrainMeasure m) {
  switch (m) {
    case StrainMeasure::kTrue:
      return "true";
    case StrainMeasure::kEngineering:
      return "engineering";
    case StrainMeasure::kLagrangian:
      return "Lagrangian (Green)";
  }
  return "true";
}

std::string measure_word(StrainMeasure m) {
  switch (m) {
    case StrainMeasure::kTrue:
      return "true";
    case StrainMeasure::kEngineering:
      return "engineering";
    case StrainMeasure::kLagrangian:
      return "Green";
  }
  return "true";
}

std::array<std::string, 2> measure_fields(StrainMeasure m) {
  switch (m) {
    case StrainMeasure::kTrue:
      return {"true1", "true2"};
    case StrainMeasure::kEngineering:
      return {"eng1", "eng2"};
    case StrainMeasure::kLagrangian:
      return {"E1", "E2"};
  }
  return {"true1", "true2"};
}

double strain_of_stretch(double l, StrainMeasure m) {
  switch (m) {
    case StrainMeasure::kTrue:
      return std::log(l);
    case StrainMeasure::kEngineering:
      return l - 1;
    case StrainMeasure::kLagrangian:
      return 0.5 * (l * l - 1);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

double principal_strain(const SurfaceStrain& s, int i, StrainMeasure m) {
  switch (m) {
    case StrainMeasure::kTrue:
      return s.true_strain(i);
    case StrainMeasure::kEngineering:
      return s.engineering(i);
    case StrainMeasure::kLagrangian:
      return s.green(i);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

MarkStrains mark_strains(const AnalysisResult& result, StrainMeasure m) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  MarkStrains out;
  out.major.reserve(result.points.size());
  out.minor.reserve(result.points.size());
  for (const PointResult& p : result.points) {
    const bool ok = p.strain && p.status == kStatusOk;
    out.major.push_back(ok ? principal_strain(*p.strain, 0, m) : kNaN);
    out.minor.push_back(ok ? principal_strain(*p.strain, 1, m) : kNaN);
  }
  return out;
}

}  // namespace sf::gsa
