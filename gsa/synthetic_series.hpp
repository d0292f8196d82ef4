#pragma once
// A synthetic stage series with exact strains per stage, for the series tests and
// bench/gsa_series_bench (gsa/series.hpp).
//
// A flat n x n grid (X, Y, 0), spacing d, deformed at stage k = 0 .. stages-1 with
// t = (k + 1) / stages by a stretch that grows linearly with t and a bulge:
//
//   x = (1 + a t) X,   y = (1 - b t) Y,   z = t h (1 - (X^2 + Y^2) / R^2),  R = 0.75 n d
//
// F = [[1 + a t, 0], [0, 1 - b t], [z,X, z,Y]] and the exact principal stretches are the
// square roots of the eigenvalues of C = F^T F (no bulge: 1 + a t and 1 - b t exactly).
// Noise (independent, per coordinate and state), marks not measured in some stages
// (status flag, NaN position) and a sigma column are optional.

#include <vector>

#include "common/io/grid_series.hpp"
#include "gsa/synthetic.hpp"

namespace sf::gsa {

struct SyntheticSeriesOptions {
  int n = 21;            // marks per side
  double spacing = 2.0;  // d, mm
  int stages = 5;
  double stretch = 0.2;       // a: engineering major strain at the last stage (no bulge)
  double contraction = 0.08;  // b
  double bulge = 0.0;         // h: height of the bulge at the last stage, mm
  double noise = 0.0;         // standard deviation per coordinate, mm
  double not_measured = 0.0;  // fraction of marks not measured in each stage (drawn per stage)
  bool with_sigma = false;    // a sigma column (= noise) in every state
  unsigned seed = 1;
};

struct SyntheticSeries {
  io::GridSeries series;
  std::vector<std::vector<ExactStrain>> exact;  // [stage][point]
};

SyntheticSeries make_synthetic_series(const SyntheticSeriesOptions& options);

}  // namespace sf::gsa
