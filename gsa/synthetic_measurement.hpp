#pragma once
// Synthetic measurements shaped like real ones: spatially correlated noise (as in
// digital image correlation, where neighbouring points share image subsets),
// localised necks and dimples, narrow strips and DIC-like scattered points, with
// the exact strains at every point. The analytic cases of gsa/synthetic.hpp flatter
// the fit (independent noise on a regular grid); these are what the automatic
// smoothing, the outlier rule and the edge treatment are measured on.
//
// Units: mm. Strains compared as Green strains of the principal stretches.

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "gsa/grid.hpp"
#include "gsa/noise_model.hpp"
#include "gsa/synthetic.hpp"

namespace sf::gsa {

// Noise per coordinate: a Gaussian random field with covariance
// sigma_correlated^2 exp(-r^2 / (2 L^2)) (L = correlation_length, r the distance
// between the points' undeformed positions) plus independent noise sigma_white.
struct NoiseModel {
  double sigma_correlated = 0.0;    // mm
  double correlation_length = 0.0;  // mm (0 with sigma_correlated > 0: invalid)
  double sigma_white = 0.0;         // mm
  // The z component's noise (correlated and independent) over the x and y components':
  // stereo DIC of a part facing the cameras measures out of plane several times worse
  // than in plane (1: isotropic). The sigmas above are the in-plane ones.
  double normal_factor = 1.0;
  double sigma_total() const;  // sqrt of the summed variances (in plane)
};

// An analytic deformation of a flat blank (Z = 0) with its exact gradient
// dx/d(X, Y) (3 x 2), from which the exact principal stretches follow.
struct Deformation {
  std::string name;
  std::string description;
  std::function<Vec3(const Vec3&)> map;
  std::function<Mat32(const Vec3&)> gradient;
  ExactStrain exact(const Vec3& X) const;
};

// Uniaxial tension of a strip along X with a neck centred at X = 0: axial stretch
// lambda(X) = 1 + base + (peak - base) exp(-X^2 / (2 w^2)) (engineering strains),
// width stretch lambda^-1/2 (incompressible, plane stress). w: the neck's half
// width parameter (mm).
Deformation neck_deformation(double base_strain, double peak_strain, double width);
// A band of strain along Y at X = 0, as a crack's opening shows ahead of it: stretch
// lambda(X) as in neck_deformation along X, none across it (x = X + u(X), y = Y).
Deformation band_deformation(double base_strain, double peak_strain, double width);
// Homogeneous stretch (l1 along X, l2 along Y) with a smooth out-of-plane dimple
// of height `amplitude` (mm) and radius parameter `radius` (mm) at (cx, cy).
Deformation dimple_deformation(double l1, double l2, double amplitude, double radius, double cx, double cy);
// A case of gsa/synthetic.hpp (gradient by central differences, error ~1e-10).
Deformation deformation_of(const SyntheticCase& c);

// Where the points are, on the undeformed blank (centred on the origin):
//   kGrid      a regular grid (marks), spacing along both axes
//   kJittered  a regular grid with each point moved by up to +-jitter spacings
//              (DIC points on a curved or tilted part, or after masking)
//   kScattered uniformly random points at the same mean density
struct PointLayout {
  enum class Kind { kGrid, kJittered, kScattered };
  Kind kind = Kind::kGrid;
  double length_x = 100.0, length_y = 100.0;  // mm
  double spacing = 5.0;                       // mm
  double jitter = 0.3;                        // fraction of the spacing (kJittered)
  bool round = false;                         // keep the ellipse inscribed in the rectangle
};

struct SyntheticMeasurementOptions {
  PointLayout layout;
  NoiseModel undeformed_noise, deformed_noise;
  int blunders = 0;           // isolated marks moved by blunder_size (deformed state)
  double blunder_size = 0.0;  // mm, 0 = 10 x the deformed noise sigma
  bool blunders_in_plane = false;  // blunders along x and y only (else in a random 3-D direction)
  unsigned seed = 1;
};

struct SyntheticMeasurement {
  GridData grid;                      // ids, positions (and i, j on kGrid)
  std::vector<Vec3> nominal;          // exact undeformed positions
  std::vector<ExactStrain> exact;     // exact strains at each point
  std::vector<double> edge_distance;  // distance of the nominal position from the layout's outline, mm
  std::vector<Index> blunder_points;  // points given a blunder
};

SyntheticMeasurement make_measurement(const Deformation& deformation, const SyntheticMeasurementOptions& options);

}  // namespace sf::gsa
