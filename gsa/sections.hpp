#pragma once
// Section lines through the fitted surfaces (docs/usage.md "Sections"): strains, thickness
// and shape sampled along a cut, for a CSV and a line plot.
//
//   plane:X,Y,Z,NX,NY,NZ   the plane through the point (X,Y,Z) with normal (NX,NY,NZ),
//                          cutting the formed part (deformed surface), in the length unit
//   curve:X,Y[,Z];X,Y[,Z];...  a polyline of points on the undeformed blank (two numbers:
//                          X, Y, with Z the blank's mean height); sampled between its points
//                          and projected onto the undeformed fitted surface, i.e. a curve
//                          of the sheet's material (surface) coordinates
//
// Only the measured region of the fits is cut (gsa/measured_region.hpp). A plane cut is
// found on a 16 x 16 sampling of every element (one point per crossed cell edge, refined
// onto the plane); its pieces are joined into branches, longest first. Arc lengths are
// measured along the sampled points on the undeformed blank and on the formed part.

#include <optional>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "gsa/analysis.hpp"
#include "gsa/midsurface.hpp"
#include "gsa/neck.hpp"
#include "gsa/strain_measure.hpp"

namespace sf::gsa {

struct SectionSpec {
  enum class Kind { kPlane, kCurve };
  Kind kind = Kind::kPlane;
  std::string text;  // as given
  Vec3 point = Vec3::Zero(), normal = Vec3::UnitX();
  std::vector<Vec3> curve;  // kCurve; NaN Z: the blank's mean height
};
// Throws sf::UsageError naming `option` ("--section 2") for text that is not a section.
SectionSpec parse_section(const std::string& text, const std::string& option);

struct SectionPoint {
  int branch = 0;
  Index element = -1;
  Vec2 xi = Vec2::Zero();
  double s_undeformed = 0, s_deformed = 0;  // arc length from the branch's start (length unit)
  Vec3 X = Vec3::Zero(), x = Vec3::Zero();  // undeformed and deformed position
  double major = 0, minor = 0;              // surface (marked face) strains in the measure
  double thickness_change_pct = 0;          // incompressible, from the surface strains
  // With a thickness (mid-surface correction): mid-surface strains, NaN otherwise.
  double mid_major = std::numeric_limits<double>::quiet_NaN(), mid_minor = mid_major, thickness = mid_major;
  double thickness_strain = 0;  // ln(h/h0) in the measure's terms: strain_of_stretch(lambda3)
};

struct Section {
  std::string name;  // "section_1"
  SectionSpec spec;
  std::vector<SectionPoint> points;  // branch 0 first (the longest), each branch in order
  int n_branches = 0;
  std::optional<NeckResult> neck;  // with evaluate_neck: on branch 0, the assessed strains
};

struct SectionOptions {
  StrainMeasure measure = StrainMeasure::kTrue;
  MidSurfaceOptions mid;  // enabled(): mid-surface strains and the thickness in mm too
  bool neck = false;      // evaluate the neck (gsa/neck.hpp) on branch 0
  int subdiv = 16;        // sampling per element side
};

// Throws sf::UsageError naming `option` when the section misses the measured part (a plane
// that does not cut it, a curve off the blank).
Section cut_section(const AnalysisResult& result, const SectionSpec& spec, const SectionOptions& options,
                    const std::string& option);

// section_N.csv: a comment block (what, units, the neck result) and one row per point.
void write_section_csv(const std::string& path, const Section& section, const SectionOptions& options,
                       const std::string& units);

}  // namespace sf::gsa
