#pragma once
// A 2-D chart (x-y plot) drawn with the scene renderer: axes with round ticks, grid, axis
// labels, dots and (dashed) lines, a legend in the right panel, optionally equal axes (one
// data unit is as long on x as on y, e.g. the major/minor principal strain plot).
// Lines are clipped to the plot area, so reference lines may be given with far ends.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "common/render/colour.hpp"
#include "common/render/scene.hpp"

namespace sf::render {

struct ChartSeries {
  enum class Style { kDots, kLine };
  std::string label;  // legend text; "" = not in the legend
  Style style = Style::kDots;
  std::vector<double> x, y;  // same size; NaN points are skipped (and break a line)
  Colour colour;
  double size_px = 3;  // dot radius or line width, at 1200 x 900 (scaled with the image)
  double dash_px = 0;  // lines: dash length (0 = solid), scaled like size_px
  double opacity = 1;
  bool sets_range = true;  // false: not used for the automatic axis range (reference lines)
};

struct Chart {
  std::string title, subtitle, footnote;
  std::string x_label, y_label;
  std::vector<ChartSeries> series;
  bool equal_axes = false;
  bool include_origin = true;
  // x_min, x_max, y_min, y_max; default: the data of the series with sets_range and the
  // points below, padded.
  std::optional<std::array<double, 4>> range;
  std::vector<Vec2> range_points;  // (x, y) points the automatic range must include
  std::string legend_title;
  std::vector<LegendEntry> extra_legend;  // appended after the series' entries
};

// Where data points land in the written image.
struct ChartFraming {
  int width = 0, height = 0;
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;  // the axes' data range
  std::array<double, 4> plot_px{};                    // plot area x0, y0, x1, y1; origin bottom left
  // Pixel position, origin top left, y down (as RgbImage).
  Vec2 to_pixel(double x, double y) const;
};

// Renders and writes the chart as PNG (see write_png for errors).
ChartFraming write_chart_png(const Chart& chart, const ImageSize& size, const std::string& path);

// Clips segment p-q to the rectangle {x_lo, y_lo, x_hi, y_hi} (Liang-Barsky), in place;
// false when nothing of it is inside.
bool clip_segment(Vec2& p, Vec2& q, const std::array<double, 4>& rect);

}  // namespace sf::render
