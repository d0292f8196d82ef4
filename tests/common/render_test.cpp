// Tests of the headless rendering layer (common/render): display guard, colours, framing,
// glyphs, determinism and the clear error when no display can be had.
//
// The pictures are small (320 x 240 or so) to keep each render near 0.1-0.3 s.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "common/core/error.hpp"
#include "common/render/chart.hpp"
#include "common/render/colour.hpp"
#include "common/render/display.hpp"
#include "common/render/scene.hpp"

namespace sf::render {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test under the build tree.
fs::path test_dir(const std::string& name) {
  const fs::path d = fs::path(SF_BINARY_DIR) / "test_output" / "render" / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

double distance(const Colour& a, const Colour& b) {
  return std::sqrt((a.r - b.r) * (a.r - b.r) + (a.g - b.g) * (a.g - b.g) + (a.b - b.b) * (a.b - b.b));
}

std::string colour_text(const Colour& c) {
  return "(" + std::to_string(std::lround(c.r * 255)) + ", " + std::to_string(std::lround(c.g * 255)) + ", " +
         std::to_string(std::lround(c.b * 255)) + ")";
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A flat n x n grid of quads over [0, 1]^2 in the z = 0 plane.
Surface flat_square(int n) {
  Surface s;
  s.points.resize((n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) s.points.row(j * (n + 1) + i) << double(i) / n, double(j) / n, 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const Index a = j * (n + 1) + i;
      s.polygons.push_back({a, a + 1, a + n + 2, a + n + 1});
    }
  return s;
}

// Scene: the square coloured by f(x, y) with `map`, exact colours.
Scene linear_field_scene(ColourMap map, double lo, double hi, bool x_direction) {
  Scene scene;
  scene.view.kind = ViewKind::kTop;
  Surface s = flat_square(8);
  ScalarColouring c;
  c.title = "field";
  c.units = "-";
  c.map = map;
  for (Index i = 0; i < s.points.rows(); ++i) {
    const double t = x_direction ? s.points(i, 0) : s.points(i, 1);
    c.values.push_back(lo + (hi - lo) * t);
  }
  c.bands = nice_bands(lo, hi, 10, map == ColourMap::kDiverging);
  c.iso_lines = false;
  s.colouring = c;
  s.shading = false;
  s.outline = false;
  scene.surfaces.push_back(s);
  return scene;
}

// ---------------------------------------------------------------------------------------

TEST(RenderColour, MapEndsAndMiddle) {
  EXPECT_LT(distance(colour_at(ColourMap::kViridis, 0), Colour::from_rgb8(68, 1, 84)), 1e-12);
  EXPECT_LT(distance(colour_at(ColourMap::kViridis, 1), Colour::from_rgb8(253, 231, 37)), 1e-12);
  EXPECT_LT(distance(colour_at(ColourMap::kViridis, -3), colour_at(ColourMap::kViridis, 0)), 1e-12);
  const Colour mid = colour_at(ColourMap::kDiverging, 0.5);
  EXPECT_GT(mid.r, 0.95);                                                                   // near white at zero
  EXPECT_GT(colour_at(ColourMap::kDiverging, 0).b, colour_at(ColourMap::kDiverging, 0).r);  // blue low
  EXPECT_GT(colour_at(ColourMap::kDiverging, 1).r, colour_at(ColourMap::kDiverging, 1).b);  // red high
}

TEST(RenderColour, NiceBandsCoverTheRangeWithRoundEdges) {
  struct Case {
    double lo, hi;
    bool symmetric;
  };
  for (const Case c : {Case{-0.0632, 0.105, false}, Case{-17.4, -2.7, false}, Case{0, 34.4, false},
                       Case{-0.0632, 0.105, true}, Case{0.1, 0.1, false}, Case{-1e-5, 3e-5, true}}) {
    const Bands b = nice_bands(c.lo, c.hi, 10, c.symmetric);
    SCOPED_TRACE(std::to_string(c.lo) + " .. " + std::to_string(c.hi));
    EXPECT_LE(b.min, std::min(c.lo, c.hi) + 1e-12);
    EXPECT_GE(b.max, std::max(c.lo, c.hi) - 1e-12);
    EXPECT_GE(b.n_bands, 3);
    EXPECT_LE(b.n_bands, 24);
    EXPECT_NEAR(b.min + b.n_bands * b.step, b.max, 1e-9 * b.step);
    // Every edge prints exactly with b.decimals.
    for (int k = 0; k <= b.n_bands; ++k) {
      const double v = b.min + k * b.step;
      EXPECT_NEAR(std::stod(format_fixed(v, b.decimals)), v, 1e-9 * b.step);
    }
    if (c.symmetric) {
      EXPECT_NEAR(b.min, -b.max, 1e-12);
      EXPECT_EQ(b.n_bands % 2, 0);  // zero is an edge
    }
  }
  EXPECT_EQ(format_fixed(-0.0001, 2), "0.00");
}

TEST(RenderParse, ViewAndSize) {
  EXPECT_EQ(parse_view("iso").kind, ViewKind::kIso);
  EXPECT_EQ(parse_view("top").kind, ViewKind::kTop);
  const View v = parse_view("1,-1,2");
  EXPECT_EQ(v.kind, ViewKind::kDirection);
  EXPECT_DOUBLE_EQ(v.direction.z(), 2.0);
  EXPECT_THROW(parse_view("diagonal"), UsageError);
  EXPECT_THROW(parse_view("0,0,0"), UsageError);
  EXPECT_THROW(parse_view("1,2"), UsageError);
  const ImageSize s = parse_size("640x480");
  EXPECT_EQ(s.width, 640);
  EXPECT_EQ(s.height, 480);
  EXPECT_THROW(parse_size("640"), UsageError);
  EXPECT_THROW(parse_size("10x10"), UsageError);
  EXPECT_THROW(parse_size("640x480px"), UsageError);
  try {
    parse_size("big", "--size");
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("--size"), std::string::npos);
  }
}

TEST(RenderDisplay, RendersWithoutDisplayVariable) {
  ::unsetenv("DISPLAY");
  const fs::path dir = test_dir("no_display");
  Scene scene = linear_field_scene(ColourMap::kViridis, 0, 1, true);
  scene.title = "No DISPLAY";
  write_png(scene, {320, 240}, (dir / "a.png").string());
  const RgbImage img = read_png_rgb((dir / "a.png").string());
  EXPECT_EQ(img.width, 320);
  EXPECT_EQ(img.height, 240);
  // Not blank: some pixels differ from the white background.
  int coloured = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) coloured += distance(img.at(x, y), {1, 1, 1}) > 0.1;
  EXPECT_GT(coloured, img.width * img.height / 10);
  // The private Xvfb was stopped and DISPLAY restored (unset).
  EXPECT_EQ(std::getenv("DISPLAY"), nullptr);
}

TEST(RenderDisplay, GuardNestsAndReusesOneServer) {
  ::unsetenv("DISPLAY");
  const auto a = acquire_display();
  const auto b = acquire_display();
  EXPECT_EQ(a.get(), b.get());
  if (!renders_without_display()) {
    ASSERT_NE(std::getenv("DISPLAY"), nullptr);
    EXPECT_EQ(std::string(std::getenv("DISPLAY")), a->display());
  }
}

// A DISPLAY that names no server is not trusted (VTK would abort on it): a private Xvfb is
// used instead, and DISPLAY is given back its old value afterwards. A second guard while
// the first is alive uses the first one's display instead of starting another server.
TEST(RenderDisplay, UnusableDisplayIsReplacedAndRestored) {
  if (renders_without_display()) GTEST_SKIP() << "this VTK renders without any display";
  ::setenv("DISPLAY", ":987", 1);  // nothing listens there
  {
    DisplayGuard outer;
    EXPECT_TRUE(outer.owns_server());
    EXPECT_NE(outer.display(), ":987");
    EXPECT_EQ(std::string(std::getenv("DISPLAY")), outer.display());
    DisplayGuard inner;
    EXPECT_FALSE(inner.owns_server());
    EXPECT_EQ(inner.display(), outer.display());
    const fs::path dir = test_dir("bad_display");
    write_png(linear_field_scene(ColourMap::kViridis, 0, 1, true), {200, 200}, (dir / "a.png").string());
    EXPECT_TRUE(fs::exists(dir / "a.png"));
  }
  ASSERT_NE(std::getenv("DISPLAY"), nullptr);
  EXPECT_EQ(std::string(std::getenv("DISPLAY")), ":987");
  ::unsetenv("DISPLAY");
}

// A linear field on a flat square seen from the top: the low end of the colour map on the
// left (x = 0), the high end on the right; for a field along y, low at the bottom.
TEST(RenderImage, LinearFieldShowsMapEndsAtTheRightSides) {
  const fs::path dir = test_dir("linear_field");
  for (const ColourMap map : {ColourMap::kViridis, ColourMap::kDiverging}) {
    for (const bool along_x : {true, false}) {
      const double lo = map == ColourMap::kViridis ? 0.0 : -1.0;
      const Scene scene = linear_field_scene(map, lo, 1.0, along_x);
      const std::string path = (dir / ("f" + std::to_string(int(map)) + std::to_string(along_x) + ".png")).string();
      const Framing fr = write_png(scene, {360, 260}, path);
      const RgbImage img = read_png_rgb(path);
      const Bands b = scene.surfaces[0].colouring->bands;
      const Colour low = colour_at(map, 0.5 / b.n_bands), high = colour_at(map, 1 - 0.5 / b.n_bands);
      const Vec3 p_low = along_x ? Vec3(0.02, 0.5, 0) : Vec3(0.5, 0.02, 0);
      const Vec3 p_high = along_x ? Vec3(0.98, 0.5, 0) : Vec3(0.5, 0.98, 0);
      const Vec2 a = fr.to_pixel(p_low), c = fr.to_pixel(p_high);
      const Colour got_low = img.at(int(std::floor(a.x())), int(std::floor(a.y())));
      const Colour got_high = img.at(int(std::floor(c.x())), int(std::floor(c.y())));
      SCOPED_TRACE(path);
      EXPECT_LT(distance(got_low, low), 0.04) << "low end " << colour_text(got_low) << " expected " << colour_text(low);
      EXPECT_LT(distance(got_high, high), 0.04)
          << "high end " << colour_text(got_high) << " expected " << colour_text(high);
      if (map == ColourMap::kDiverging) {
        EXPECT_GT(got_low.b, got_low.r + 0.3);
        EXPECT_GT(got_high.r, got_high.b + 0.3);
      }
      // The square fills its frame: its corners land inside the image.
      for (const Vec3& corner : {Vec3(0, 0, 0), Vec3(1, 1, 0)}) {
        const Vec2 p = fr.to_pixel(corner);
        EXPECT_GT(p.x(), 0);
        EXPECT_LT(p.x(), fr.width);
        EXPECT_GT(p.y(), 0);
        EXPECT_LT(p.y(), fr.height);
      }
    }
  }
}

// Arrows of a homogeneous stretch (tension along x, compression along y) at a grid of
// points: the tension colour is found along x beyond each point, the compression colour
// along y, and the background (surface grey) beyond the arrow tips.
TEST(RenderImage, ArrowsLandWhereExpected) {
  const fs::path dir = test_dir("arrows");
  Scene scene;
  scene.view.kind = ViewKind::kTop;
  Surface s = flat_square(4);
  s.shading = false;
  s.outline = false;
  s.colour = {0.9, 0.9, 0.9};
  scene.surfaces.push_back(s);
  const Colour red{0.8, 0.1, 0.1}, blue{0.1, 0.3, 0.8};
  GlyphSet tension, compression;
  tension.colour = red;
  compression.colour = blue;
  tension.width = compression.width = 0.012;
  const double L = 0.08, gap = 0.02;
  std::vector<Vec3> centres;
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) centres.emplace_back(0.25 + 0.25 * i, 0.25 + 0.25 * j, 0);
  for (const Vec3& c : centres)
    for (const double sgn : {-1.0, 1.0}) {
      tension.tails.push_back(c + sgn * gap * Vec3::UnitX());
      tension.heads.push_back(c + sgn * (gap + L) * Vec3::UnitX());  // heads out
      compression.tails.push_back(c + sgn * (gap + L) * Vec3::UnitY());
      compression.heads.push_back(c + sgn * gap * Vec3::UnitY());  // heads in
    }
  scene.glyphs = {tension, compression};
  const std::string path = (dir / "arrows.png").string();
  const Framing fr = write_png(scene, {480, 360}, path);
  const RgbImage img = read_png_rgb(path);
  auto colour_at_model = [&](const Vec3& p) {
    const Vec2 q = fr.to_pixel(p);  // pixel (i, j) covers [i, i + 1) x [j, j + 1)
    return img.at(int(std::floor(q.x())), int(std::floor(q.y())));
  };
  for (const Vec3& c : centres) {
    SCOPED_TRACE("arrow pair at " + std::to_string(c.x()) + ", " + std::to_string(c.y()));
    for (const double sgn : {-1.0, 1.0}) {
      EXPECT_LT(distance(colour_at_model(c + sgn * (gap + 0.3 * L) * Vec3::UnitX()), red), 0.1);
      EXPECT_LT(distance(colour_at_model(c + sgn * (gap + 0.7 * L) * Vec3::UnitY()), blue), 0.1);
      // Beyond the tips: the surface.
      EXPECT_LT(distance(colour_at_model(c + sgn * (gap + L + 0.03) * Vec3::UnitX()), {0.9, 0.9, 0.9}), 0.05);
      EXPECT_LT(distance(colour_at_model(c + sgn * (gap + L + 0.03) * Vec3::UnitY()), {0.9, 0.9, 0.9}), 0.05);
    }
    // Heads: the tension arrow is wider near its outer end (head out), the compression
    // arrow near the centre (head in). Probe just inside the head's base, off the axis by
    // more than the shaft's half width and less than the head's.
    const double w = 0.012, hl = std::min(4 * w, 0.6 * L), off = 0.5 * (w / 2 + 3.2 * w / 2);
    const double near_base = gap + L - hl + 0.005, near_centre = gap + 0.012;
    EXPECT_LT(distance(colour_at_model(c + near_base * Vec3::UnitX() + off * Vec3::UnitY()), red), 0.15);
    EXPECT_GT(distance(colour_at_model(c + near_centre * Vec3::UnitX() + off * Vec3::UnitY()), red), 0.3);
    EXPECT_LT(distance(colour_at_model(c + (gap + hl - 0.005) * Vec3::UnitY() + off * Vec3::UnitX()), blue), 0.15);
    EXPECT_GT(distance(colour_at_model(c + (gap + L - 0.008) * Vec3::UnitY() + off * Vec3::UnitX()), blue), 0.3);
  }
}

TEST(RenderImage, SameSceneGivesIdenticalBytes) {
  const fs::path dir = test_dir("determinism");
  Scene scene = linear_field_scene(ColourMap::kDiverging, -0.2, 0.3, true);
  scene.title = "Determinism";
  scene.subtitle = "same data, same bytes";
  scene.surfaces[0].shading = true;
  scene.surfaces[0].colouring->iso_lines = true;
  scene.view.kind = ViewKind::kIso;
  write_png(scene, {320, 240}, (dir / "a.png").string());
  write_png(scene, {320, 240}, (dir / "b.png").string());
  const std::string a = read_bytes(dir / "a.png"), b = read_bytes(dir / "b.png");
  EXPECT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << "the two renders differ";
  // No temporary files left behind.
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  EXPECT_EQ(n, 2);
}

TEST(RenderChart, DotsAndClippedLinesLandOnTheAxes) {
  const fs::path dir = test_dir("chart");
  Chart chart;
  chart.title = "Chart";
  chart.x_label = "minor";
  chart.y_label = "major";
  chart.equal_axes = true;
  ChartSeries dots;
  dots.label = "marks";
  dots.x = {-0.1, 0.0, 0.1};
  dots.y = {0.2, 0.1, 0.1};
  dots.colour = {0.1, 0.2, 0.7};
  dots.size_px = 6;
  ChartSeries diag;
  diag.label = "equibiaxial";
  diag.style = ChartSeries::Style::kLine;
  diag.x = {-10, 10};
  diag.y = {-10, 10};
  diag.colour = {0.9, 0.5, 0.0};
  diag.size_px = 8;
  diag.sets_range = false;
  chart.series = {diag, dots};
  const std::string path = (dir / "chart.png").string();
  const ChartFraming cf = write_chart_png(chart, {480, 360}, path);
  const RgbImage img = read_png_rgb(path);
  // Equal axes: one data unit spans as many pixels on x as on y.
  const double kx = (cf.plot_px[2] - cf.plot_px[0]) / (cf.x_max - cf.x_min);
  const double ky = (cf.plot_px[3] - cf.plot_px[1]) / (cf.y_max - cf.y_min);
  EXPECT_NEAR(kx, ky, 1e-9 * kx);
  for (std::size_t i = 0; i < dots.x.size(); ++i) {
    const Vec2 p = cf.to_pixel(dots.x[i], dots.y[i]);
    EXPECT_LT(distance(img.at(int(std::floor(p.x())), int(std::floor(p.y()))), dots.colour), 0.1) << "dot " << i;
  }
  const Vec2 q = cf.to_pixel(0.05, 0.05);  // on the diagonal
  EXPECT_LT(distance(img.at(int(std::floor(q.x())), int(std::floor(q.y()))), diag.colour), 0.15);
  // The diagonal is clipped: nothing of it outside the plot area (above its top edge).
  const Vec2 top_left = cf.to_pixel(cf.x_max, cf.y_max);
  EXPECT_LT(distance(img.at(int(top_left.x()) + 4, int(top_left.y()) - 4), {1, 1, 1}), 0.05);
}

// With no DISPLAY and no Xvfb on PATH, rendering throws sf::Error with a clear message
// instead of letting VTK abort the process. Run in a child process (its environment).
TEST(RenderDisplay, ClearErrorWhenNoDisplayCanBeHad) {
  if (renders_without_display()) GTEST_SKIP() << "this VTK renders without any display";
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::close(fds[0]);
    ::unsetenv("DISPLAY");
    ::setenv("PATH", "/nonexistent-sf-test", 1);
    int code = 3;
    std::string message = "no error";
    try {
      Scene scene = linear_field_scene(ColourMap::kViridis, 0, 1, true);
      write_png(scene, {200, 200}, "/tmp/sf-render-should-not-exist.png");
    } catch (const Error& e) {
      message = e.what();
      code = 0;
    } catch (const std::exception& e) {
      message = e.what();
      code = 2;
    }
    [[maybe_unused]] const auto w = ::write(fds[1], message.data(), message.size());
    ::_exit(code);
  }
  ::close(fds[1]);
  std::string message;
  char buf[512];
  ssize_t n = 0;
  while ((n = ::read(fds[0], buf, sizeof buf)) > 0) message.append(buf, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "child died by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 0) << message;
  EXPECT_NE(message.find("Xvfb"), std::string::npos) << message;
  EXPECT_NE(message.find("DISPLAY"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists("/tmp/sf-render-should-not-exist.png"));
}

}  // namespace
}  // namespace sf::render
