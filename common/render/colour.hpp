#pragma once
// Colours, colour maps and "nice" colour ranges for the pictures. No VTK here.
//
// Colour maps (sRGB, linear interpolation between the tabulated stops):
//  - kViridis: perceptually uniform, dark violet (low) -> yellow (high); the default for
//    fields of one sign;
//  - kDiverging: ColorBrewer RdBu reversed, dark blue (low) -> near white (middle) -> dark red
//    (high); for signed fields, centred on 0 (blue = negative = compression / thinning,
//    red = positive).

#include <cstdint>
#include <string>
#include <vector>

namespace sf::render {

struct Colour {
  double r = 0, g = 0, b = 0;  // sRGB components in [0, 1]
  static Colour from_rgb8(int r8, int g8, int b8) { return {r8 / 255.0, g8 / 255.0, b8 / 255.0}; }
};

enum class ColourMap { kViridis, kDiverging };

// The map's colour at t in [0, 1] (clamped; NaN gives the middle).
Colour colour_at(ColourMap map, double t);

// Equal-width colour bands with round edges, e.g. [-0.06, 0.11] step 0.01.
struct Bands {
  double min = 0, max = 1;  // outer edges; max > min
  double step = 0.1;        // band width; (max - min) / step bands
  int n_bands = 10;
  int decimals = 1;  // decimals that print every edge exactly ("%.*f")
};

// Round bands covering [lo, hi] with about `target` bands (step 1, 2, 2.5 or 5 x 10^k).
// symmetric: the range is made symmetric about 0 (for a diverging map). A zero-width range
// is widened around its value so the result is always valid.
Bands nice_bands(double lo, double hi, int target = 10, bool symmetric = false);

// Tick positions for an axis from lo to hi with about `target` ticks at round values.
std::vector<double> nice_ticks(double lo, double hi, int target, int* decimals = nullptr);

// Formats `value` with `decimals` decimals ("-0.05"; never "-0.00").
std::string format_fixed(double value, int decimals);

}  // namespace sf::render
