#pragma once
// Headless pictures: a plain-data scene in, a PNG out. VTK is used only in the .cpp files.
//
//   render::Scene scene;
//   scene.title = "Thickness change";
//   render::Surface& s = scene.surfaces.emplace_back();
//   s.points = ...; s.polygons = ...;                    // model units, e.g. mm
//   render::ScalarColouring c;
//   c.values = ...; c.title = "Thickness change"; c.units = "%";
//   c.bands = render::nice_bands(lo, hi, 10);
//   s.colouring = c;
//   render::write_png(scene, {1200, 900}, "thickness.png");
//
// Picture layout (pixels, origin at the bottom left): a title band at the top, a panel on
// the right for the colour bar and the legend (only when there is one), an optional
// footnote line at the bottom, and the part framed in the rest with a parallel projection
// (one scale everywhere, so a legend can state lengths). White background, no
// multisampling differences between runs: the same scene gives the same bytes.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/render/colour.hpp"

namespace sf::render {

// ---------------------------------------------------------------------------------------
// 3-D content (model units)

// A scalar field drawn as colours on a surface, with a colour bar in the right panel.
struct ScalarColouring {
  std::string title;           // colour bar title, e.g. "Thickness change"
  std::string units;           // e.g. "%", "-" (dimensionless), "deg"; shown as "[units]"
  std::vector<double> values;  // one per surface point; NaN = no value (drawn grey)
  ColourMap map = ColourMap::kViridis;
  Bands bands;            // colour range [bands.min, bands.max] and band edges (nice_bands())
  bool banded = true;     // discrete colour bands; false: a smooth map over the range
  bool iso_lines = true;  // dark lines along the interior band edges
  bool colour_bar = true;
};

// A surface of triangles and quadrilaterals (any convex polygons).
struct Surface {
  Points3 points;                            // n_points x 3
  std::vector<std::vector<Index>> polygons;  // 0-based point indices, >= 3 each
  std::optional<ScalarColouring> colouring;  // none: plain `colour`
  Colour colour{0.88, 0.88, 0.88};
  bool shading = true;                    // mild headlight shading for a 3-D impression (surfaces facing the
                                          // camera keep their exact colour); false: exact colours everywhere
  bool outline = true;                    // the boundary edges as a dark line
  std::vector<std::vector<Index>> lines;  // extra polylines on the surface (e.g. element edges)
  Colour line_colour{0.6, 0.6, 0.6};
};

// Flat arrows or line segments, drawn as ribbons facing the camera, unlit (exact colour).
struct GlyphSet {
  enum class Kind { kArrow, kSegment };
  Kind kind = Kind::kArrow;
  std::vector<Vec3> tails;  // arrow: from tail to head (the head is drawn at `heads[i]`);
  std::vector<Vec3> heads;  // segment: the two ends. Same size as `tails`.
  Colour colour;
  double width = 0;        // shaft width, model units (0: 1/250 of the part's size)
  double head_length = 0;  // model units (0: 4 widths); at most 60 % of each arrow
  double head_width = 0;   // model units (0: 3.2 widths)
  double lift = 0;         // moved this far toward the camera, off the surface (0: automatic)
};

// ---------------------------------------------------------------------------------------
// Camera

enum class ViewKind { kAuto, kIso, kTop, kFront, kSide, kDirection };

// kAuto looks along the area-weighted mean normal of the surfaces (from its side with
// z >= 0); kTop from +Z (Y up), kFront from -Y (Z up), kSide from +X (Z up), kIso from
// (1, -1, 1) (Z up), kDirection from `direction` (from the part toward the eye).
struct View {
  ViewKind kind = ViewKind::kAuto;
  Vec3 direction = Vec3::UnitZ();
};

// "auto", "iso", "top", "front", "side" or a direction "x,y,z". Throws sf::UsageError
// naming `option` otherwise.
View parse_view(const std::string& text, const std::string& option = "--view");
std::string view_name(const View& view);

// ---------------------------------------------------------------------------------------
// 2-D content (pixels, origin at the bottom left of the image)

struct Text2D {
  std::string text;  // UTF-8, one line
  Vec2 at = Vec2::Zero();
  double size_px = 16;
  Colour colour{0.1, 0.1, 0.1};
  int halign = -1;  // -1 left, 0 centre, 1 right of `at`
  int valign = -1;  // -1 bottom, 0 middle, 1 top at `at`
  bool bold = false;
  double angle_deg = 0;  // counter-clockwise
};

// A filled convex polygon (closed = true) or a polyline of `width_px` (optionally dashed).
struct Shape2D {
  std::vector<Vec2> points;
  Colour colour;
  double opacity = 1.0;
  bool filled = true;
  double width_px = 1.0;  // polyline width
  double dash_px = 0.0;   // polyline: dash and gap length (0 = solid)
};

// One row of the legend in the right panel: a symbol and a label.
struct LegendEntry {
  enum class Kind { kArrow, kLine, kDot, kSwatch, kNone };
  Kind kind = Kind::kSwatch;
  Colour colour;
  std::string label;
  double dash_px = 0;       // kLine
  double width_px = 2;      // kLine width, kDot radius
  double model_length = 0;  // kArrow: drawn this long in model units, to the picture's scale
  int glyph_set = -1;       // kArrow: take width and head from this GlyphSet
};

struct Scene {
  std::string title;     // top centre, large
  std::string subtitle;  // below the title
  std::string footnote;  // bottom left, small
  std::vector<Surface> surfaces;
  std::vector<GlyphSet> glyphs;
  View view;
  std::string legend_title;
  std::vector<LegendEntry> legend;
  // Overlay drawn over everything else, in order.
  std::vector<Shape2D> shapes;
  std::vector<Text2D> texts;
  // Frame the 3-D content into this pixel rectangle (x0, y0, x1, y1) instead of the
  // automatic one (e.g. to leave room for overlay content).
  std::optional<std::array<double, 4>> frame_px;
};

struct ImageSize {
  int width = 1200;
  int height = 900;
};
// "WxH" with 200 <= W, H <= 8000. Throws sf::UsageError naming `option` otherwise.
ImageSize parse_size(const std::string& text, const std::string& option = "--size");

// Where model points land in the written image.
struct Framing {
  int width = 0, height = 0;
  double pixels_per_unit = 0;  // 0 when the scene had no 3-D content
  Vec3 focal = Vec3::Zero(), right = Vec3::UnitX(), up = Vec3::UnitY();
  Vec3 toward_eye = Vec3::UnitZ();
  // Pixel position (origin top left, y down: as in image viewers and RgbImage).
  Vec2 to_pixel(const Vec3& p) const;
};

// Pixel layout the renderer will use for a scene of this size (for overlay authors).
struct Layout {
  double scale = 1;       // font scale: height / 900
  double title_band = 0;  // pixels at the top used by title and subtitle
  double footnote_band = 0;
  double panel_left = 0;          // x where the right panel starts (== width when no panel)
  std::array<double, 4> frame{};  // the 3-D frame (x0, y0, x1, y1), origin bottom left
};
Layout layout_of(const Scene& scene, const ImageSize& size);

// Width and height in pixels of one line of text.
Vec2 text_extent(const std::string& text, double size_px, bool bold = false);

// Renders the scene off screen (acquiring a display as display.hpp describes) and writes a
// PNG atomically. Throws sf::Error when no display can be had or the file cannot be
// written; std::invalid_argument for inconsistent input (an index out of range, a field of
// the wrong length).
Framing write_png(const Scene& scene, const ImageSize& size, const std::string& path);

// An RGB image read back (tests, checks). Row 0 is the top row.
struct RgbImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> pixels;  // width * height * 3, row-major from the top
  Colour at(int x, int y) const;     // x right, y down
};
// Throws sf::Error "PATH: cannot read PNG" when it cannot.
RgbImage read_png_rgb(const std::string& path);

}  // namespace sf::render
