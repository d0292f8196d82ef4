#include "common/render/chart.hpp"

#include <algorithm>
#include <cmath>

namespace sf::render {

namespace {

const Colour kInk{0.15, 0.15, 0.15};


std::vector<double> ticks_with_step(double lo, double hi, double step) {
  std::vector<double> t;
  for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k += 1)
    t.push_back(std::abs(k) < 0.5 ? 0.0 : k * step);
  return t;
}

Shape2D line(std::vector<Vec2> pts, const Colour& c, double width, double dash = 0, double opacity = 1) {
  Shape2D s;
  s.points = std::move(pts);
  s.colour = c;
  s.filled = false;
  s.width_px = width;
  s.dash_px = dash;
  s.opacity = opacity;
  return s;
}

}  // namespace

Vec2 ChartFraming::to_pixel(double x, double y) const {
  const double px = plot_px[0] + (x - x_min) / (x_max - x_min) * (plot_px[2] - plot_px[0]);
  const double py = plot_px[1] + (y - y_min) / (y_max - y_min) * (plot_px[3] - plot_px[1]);
  return {px, height - py};
}

ChartFraming write_chart_png(const Chart& chart, const ImageSize& size, const std::string& path) {
  Scene scene;
  scene.title = chart.title;
  scene.subtitle = chart.subtitle;
  scene.footnote = chart.footnote;
  scene.legend_title = chart.legend_title;
  const double f0 = std::max(0.25, std::min(size.width / 1200.0, size.height / 900.0));
  for (const ChartSeries& s : chart.series) {
    if (s.label.empty()) continue;
    LegendEntry e;
    e.label = s.label;
    e.colour = s.colour;
    if (s.style == ChartSeries::Style::kDots) {
      e.kind = LegendEntry::Kind::kDot;
      e.width_px = std::max(2.0, s.size_px * f0 * 1.3);
    } else {
      e.kind = LegendEntry::Kind::kLine;
      e.width_px = std::max(1.0, s.size_px * f0);
      e.dash_px = s.dash_px * f0;
    }
    scene.legend.push_back(e);
  }
  for (const LegendEntry& e : chart.extra_legend) scene.legend.push_back(e);
  const Layout layout = layout_of(scene, size);
  const double f = layout.scale;
  const double tick_font = std::max(8.0, std::round(15 * f));
  const double label_font = std::max(8.0, std::round(17 * f));

  // Data range.
  double x0 = HUGE_VAL, x1 = -HUGE_VAL, y0 = HUGE_VAL, y1 = -HUGE_VAL;
  for (const ChartSeries& s : chart.series) {
    if (!s.sets_range) continue;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
        x0 = std::min(x0, s.x[i]);
        x1 = std::max(x1, s.x[i]);
        y0 = std::min(y0, s.y[i]);
        y1 = std::max(y1, s.y[i]);
      }
  }
  for (const Vec2& p : chart.range_points)
    if (p.allFinite()) {
      x0 = std::min(x0, p.x());
      x1 = std::max(x1, p.x());
      y0 = std::min(y0, p.y());
      y1 = std::max(y1, p.y());
    }
  if (chart.range) {
    x0 = (*chart.range)[0];
    x1 = (*chart.range)[1];
    y0 = (*chart.range)[2];
    y1 = (*chart.range)[3];
  } else {
    if (!(x1 >= x0)) x0 = -0.1, x1 = 0.1, y0 = -0.1, y1 = 0.1;
    if (chart.include_origin) {
      x0 = std::min(x0, 0.0);
      x1 = std::max(x1, 0.0);
      y0 = std::min(y0, 0.0);
      y1 = std::max(y1, 0.0);
    }
    const double span = std::max({x1 - x0, y1 - y0, 1e-9});
    const double padx = 0.06 * (chart.equal_axes ? span : std::max(x1 - x0, 1e-9 * span));
    const double pady = 0.06 * (chart.equal_axes ? span : std::max(y1 - y0, 1e-9 * span));
    x0 -= padx;
    x1 += padx;
    y0 -= pady;
    y1 += pady;
  }
  if (!(x1 > x0)) x1 = x0 + 1;
  if (!(y1 > y0)) y1 = y0 + 1;

  // Plot area inside the frame, leaving room for ticks and axis labels.
  const auto& fr = layout.frame;
  int dec = 0;
  double ytick_w = 0;
  for (double t : nice_ticks(y0, y1, 8, &dec))
    ytick_w = std::max(ytick_w, text_extent(format_fixed(t, dec), tick_font)[0]);
  const double left = ytick_w + 12 * f + label_font * 1.4 + 6 * f;
  const double bottom = tick_font * 1.3 + 10 * f + label_font * 1.4 + 4 * f;
  std::array<double, 4> plot = {fr[0] + left, fr[1] + bottom, fr[2] - 16 * f, fr[3] - 10 * f};
  const double pw = std::max(10.0, plot[2] - plot[0]), ph = std::max(10.0, plot[3] - plot[1]);
  plot[2] = plot[0] + pw;
  plot[3] = plot[1] + ph;
  if (chart.equal_axes) {
    const double u = std::max((x1 - x0) / pw, (y1 - y0) / ph);
    const double cx = (x0 + x1) / 2, cy = (y0 + y1) / 2;
    x0 = cx - u * pw / 2;
    x1 = cx + u * pw / 2;
    y0 = cy - u * ph / 2;
    y1 = cy + u * ph / 2;
  }
  ChartFraming cf;
  cf.width = size.width;
  cf.height = size.height;
  cf.x_min = x0;
  cf.x_max = x1;
  cf.y_min = y0;
  cf.y_max = y1;
  cf.plot_px = plot;
  auto px = [&](double x, double y) {
    return Vec2(plot[0] + (x - x0) / (x1 - x0) * pw, plot[1] + (y - y0) / (y1 - y0) * ph);
  };

  // Ticks: the same step on both axes when they are equal.
  int xdec = 0, ydec = 0;
  const double px_per_tick = 95 * f;
  std::vector<double> xt = nice_ticks(x0, x1, std::max(2, static_cast<int>(pw / px_per_tick)), &xdec);
  std::vector<double> yt = nice_ticks(y0, y1, std::max(2, static_cast<int>(ph / px_per_tick)), &ydec);
  if (chart.equal_axes && xt.size() > 1 && yt.size() > 1) {
    // One data unit is as long on both axes: use the finer of the two steps on both.
    const double sx = xt[1] - xt[0], sy = yt[1] - yt[0];
    if (sx < sy) yt = ticks_with_step(y0, y1, sx);
    if (sy < sx) xt = ticks_with_step(x0, x1, sy);
    const int d = sx < sy ? xdec : sy < sx ? ydec : std::max(xdec, ydec);
    xdec = ydec = d;
  }
  const Colour grid{0.88, 0.88, 0.88}, zero{0.55, 0.55, 0.55};
  for (double t : xt) scene.shapes.push_back(line({px(t, y0), px(t, y1)}, grid, std::max(1.0, f)));
  for (double t : yt) scene.shapes.push_back(line({px(x0, t), px(x1, t)}, grid, std::max(1.0, f)));
  if (x0 < 0 && x1 > 0) scene.shapes.push_back(line({px(0, y0), px(0, y1)}, zero, std::max(1.0, 1.2 * f)));
  if (y0 < 0 && y1 > 0) scene.shapes.push_back(line({px(x0, 0), px(x1, 0)}, zero, std::max(1.0, 1.2 * f)));

  // Series.
  for (const ChartSeries& s : chart.series) {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    if (s.style == ChartSeries::Style::kDots) {
      const double r = std::max(1.2, s.size_px * f);
      for (std::size_t i = 0; i < n; ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        const Vec2 c = px(s.x[i], s.y[i]);
        if (c.x() < plot[0] || c.x() > plot[2] || c.y() < plot[1] || c.y() > plot[3]) continue;
        Shape2D dot;
        dot.colour = s.colour;
        dot.opacity = s.opacity;
        for (int k = 0; k < 12; ++k)
          dot.points.emplace_back(c + r * Vec2(std::cos(k * kPi / 6), std::sin(k * kPi / 6)));
        scene.shapes.push_back(std::move(dot));
      }
      continue;
    }
    std::vector<Vec2> piece;
    auto flush = [&] {
      if (piece.size() >= 2)
        scene.shapes.push_back(line(piece, s.colour, std::max(1.0, s.size_px * f), s.dash_px * f, s.opacity));
      piece.clear();
    };
    for (std::size_t i = 0; i + 1 < n; ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || !std::isfinite(s.x[i + 1]) ||
          !std::isfinite(s.y[i + 1])) {
        flush();
        continue;
      }
      Vec2 a = px(s.x[i], s.y[i]), b = px(s.x[i + 1], s.y[i + 1]);
      const Vec2 a0 = a;
      if (!clip_segment(a, b, plot)) {
        flush();
        continue;
      }
      if (!piece.empty() && ((piece.back() - a).norm() > 1e-6 || (a - a0).norm() > 1e-6)) flush();
      if (piece.empty()) piece.push_back(a);
      piece.push_back(b);
    }
    flush();
  }

  // Frame, ticks and labels.
  const double lw = std::max(1.0, 1.3 * f);
  scene.shapes.push_back(line(
      {{plot[0], plot[1]}, {plot[2], plot[1]}, {plot[2], plot[3]}, {plot[0], plot[3]}, {plot[0], plot[1]}}, kInk, lw));
  const double tick = 6 * f;
  for (double t : xt) {
    const Vec2 p = px(t, y0);
    scene.shapes.push_back(line({p, p - Vec2(0, tick)}, kInk, lw));
    scene.texts.push_back({format_fixed(t, xdec), p - Vec2(0, tick + 3 * f), tick_font, kInk, 0, 1, false, 0});
  }
  for (double t : yt) {
    const Vec2 p = px(x0, t);
    scene.shapes.push_back(line({p, p - Vec2(tick, 0)}, kInk, lw));
    scene.texts.push_back({format_fixed(t, ydec), p - Vec2(tick + 4 * f, 0), tick_font, kInk, 1, 0, false, 0});
  }
  scene.texts.push_back({chart.x_label, Vec2((plot[0] + plot[2]) / 2, plot[1] - tick - 3 * f - tick_font * 1.3 - 8 * f),
                         label_font, kInk, 0, 1, false, 0});
  scene.texts.push_back({chart.y_label, Vec2(plot[0] - tick - 4 * f - ytick_w - 12 * f, (plot[1] + plot[3]) / 2),
                         label_font, kInk, 0, -1, false, 90});  // justified in the text's own frame
  write_png(scene, size, path);
  return cf;
}

bool clip_segment(Vec2& p, Vec2& q, const std::array<double, 4>& r) {
  double t0 = 0, t1 = 1;
  const Vec2 d = q - p;
  const double pk[4] = {-d.x(), d.x(), -d.y(), d.y()};
  const double qk[4] = {p.x() - r[0], r[2] - p.x(), p.y() - r[1], r[3] - p.y()};
  for (int k = 0; k < 4; ++k) {
    if (pk[k] == 0) {
      if (qk[k] < 0) return false;
      continue;
    }
    const double t = qk[k] / pk[k];
    if (pk[k] < 0)
      t0 = std::max(t0, t);
    else
      t1 = std::min(t1, t);
    if (t0 > t1) return false;
  }
  const Vec2 a = p + t0 * d, b = p + t1 * d;
  p = a;
  q = b;
  return true;
}

}  // namespace sf::render
