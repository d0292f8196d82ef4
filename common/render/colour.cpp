#include "common/render/colour.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace sf::render {

namespace {

// matplotlib's viridis at t = 0, 0.1, ..., 1.
constexpr std::array<std::array<int, 3>, 11> kViridisStops = {{{68, 1, 84},
                                                               {72, 36, 117},
                                                               {65, 68, 135},
                                                               {53, 95, 141},
                                                               {42, 120, 142},
                                                               {33, 145, 140},
                                                               {34, 168, 132},
                                                               {68, 191, 112},
                                                               {122, 209, 81},
                                                               {189, 223, 38},
                                                               {253, 231, 37}}};

// ColorBrewer RdBu (11 classes), reversed: blue (low) to red (high).
constexpr std::array<std::array<int, 3>, 11> kDivergingStops = {{{5, 48, 97},
                                                                 {33, 102, 172},
                                                                 {67, 147, 195},
                                                                 {146, 197, 222},
                                                                 {209, 229, 240},
                                                                 {247, 247, 247},
                                                                 {253, 219, 199},
                                                                 {244, 165, 130},
                                                                 {214, 96, 77},
                                                                 {178, 24, 43},
                                                                 {103, 0, 31}}};

template <std::size_t N>
Colour interpolate(const std::array<std::array<int, 3>, N>& stops, double t) {
  if (std::isnan(t)) t = 0.5;
  t = std::clamp(t, 0.0, 1.0);
  const double x = t * static_cast<double>(N - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(x), N - 2);
  const double f = x - static_cast<double>(i);
  const auto& a = stops[i];
  const auto& b = stops[i + 1];
  return {((1 - f) * a[0] + f * b[0]) / 255.0, ((1 - f) * a[1] + f * b[1]) / 255.0,
          ((1 - f) * a[2] + f * b[2]) / 255.0};
}

// The round step (1, 2, 2.5, 5 x 10^k) nearest above `raw`, and the decimals it needs.
double nice_step(double raw, int* decimals) {
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double mantissas[] = {1.0, 2.0, 2.5, 5.0, 10.0};
  double m = 10.0;
  for (double c : mantissas)
    if (c * p >= raw * (1 - 1e-9)) {
      m = c;
      break;
    }
  const double step = m * p;
  if (decimals) {
    int d = static_cast<int>(-std::floor(std::log10(step) + 1e-9));
    if (m == 2.5) d += 1;
    *decimals = std::max(0, d);
  }
  return step;
}

}  // namespace

Colour colour_at(ColourMap map, double t) {
  return map == ColourMap::kViridis ? interpolate(kViridisStops, t) : interpolate(kDivergingStops, t);
}

Bands nice_bands(double lo, double hi, int target, bool symmetric) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0, hi = 1;
  if (lo > hi) std::swap(lo, hi);
  if (symmetric) {
    const double m = std::max(std::abs(lo), std::abs(hi));
    lo = -m;
    hi = m;
  }
  if (hi - lo <= 1e-12 * std::max(1.0, std::abs(hi))) {
    const double w = std::abs(hi) > 0 ? 0.05 * std::abs(hi) : 0.01;
    lo -= w;
    hi += w;
  }
  target = std::max(target, 2);
  Bands b;
  b.step = nice_step((hi - lo) / target, &b.decimals);
  if (symmetric) {
    // An even number of bands, so 0 is an edge.
    const double half = std::ceil(hi / b.step - 1e-9);
    b.min = -half * b.step;
    b.max = half * b.step;
  } else {
    b.min = std::floor(lo / b.step + 1e-9) * b.step;
    b.max = std::ceil(hi / b.step - 1e-9) * b.step;
    if (b.max <= b.min) b.max = b.min + b.step;
  }
  b.n_bands = static_cast<int>(std::lround((b.max - b.min) / b.step));
  return b;
}

std::vector<double> nice_ticks(double lo, double hi, int target, int* decimals) {
  if (lo > hi) std::swap(lo, hi);
  if (hi - lo <= 0) hi = lo + 1;
  int d = 0;
  const double step = nice_step((hi - lo) / std::max(target, 1), &d);
  if (decimals) *decimals = d;
  std::vector<double> ticks;
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k += 1)
    ticks.push_back(std::abs(k) < 0.5 ? 0.0 : k * step);
  return ticks;
}

std::string format_fixed(double value, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", std::max(0, decimals), value);
  std::string s = buf;
  // "-0.00" -> "0.00"
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

}  // namespace sf::render
