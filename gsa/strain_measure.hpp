#pragma once
// Strain measures: which strain a picture, a forming limit curve or a margin is in, and the
// marks' principal strains in one of them (docs/usage.md, "--measure").
//
//   measure       formula          columns of strains.csv and the .vtp files
//   true          ln(lambda)       true1, true2
//   engineering   lambda - 1       eng1, eng2
//   Lagrangian    (lambda^2-1)/2   E1, E2     (Green)

#include <array>
#include <string>
#include <vector>

#include "gsa/analysis.hpp"
#include "gsa/strain.hpp"

namespace sf::gsa {

enum class StrainMeasure { kTrue, kEngineering, kLagrangian };

// "true", "engineering", "Lagrangian (Green)": for sentences.
std::string measure_name(StrainMeasure m);
// "true", "engineering", "Green": for titles and labels.
std::string measure_word(StrainMeasure m);
// The major and minor columns of the measure: {"true1", "true2"}, {"eng1", "eng2"}, {"E1", "E2"}.
std::array<std::string, 2> measure_fields(StrainMeasure m);
// Strain of a principal stretch in the measure.
double strain_of_stretch(double stretch, StrainMeasure m);
// Principal strain i (0 major, 1 minor) of `s` in the measure, the number strains.csv holds.
double principal_strain(const SurfaceStrain& s, int i, StrainMeasure m);

// Major and minor strain of every mark in one measure; NaN where a mark has no strain or
// its status is not ok.
struct MarkStrains {
  std::vector<double> major, minor;
};
MarkStrains mark_strains(const AnalysisResult& result, StrainMeasure m);

// The path of one point through the stages of a series (gsa/series.hpp), in a measure.
struct StrainPath {
  Index point = -1;
  std::string id;
  std::vector<double> major, minor;  // one per stage; NaN where the point has no strain
};

}  // namespace sf::gsa
