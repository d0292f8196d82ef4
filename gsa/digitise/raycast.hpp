#pragma once
// Synthetic photographs of a gridded sheet with exact ground truth: an analytic,
// anti-aliased ray-caster (tests, the benchmark and `gsa synth-images`).
//
// Each pixel's ray comes from the calibrated camera model itself (pinhole plus
// Brown-Conrady distortion, camera.hpp), so the lens distortion in the pictures is exactly
// the model that calibration recovers. The ray meets the sheet's analytic surface (a
// plane, a spherical dome or a cylindrical bend); the hit point's MATERIAL coordinates
// (X, Y) decide the printed pattern (dots, lines, chessboard, circle grids), so the marks
// are printed on the blank and deform with it, exactly as in forming. Anti-aliasing: the
// material coordinates are computed at the pixel corners; a pixel whose footprint can
// contain a pattern edge is supersampled (a Fibonacci lattice of >= N^2 points) through the bilinear corner map (exact to
// second order in the pixel size); pixels that straddle the part's edge or an occluder are
// supersampled with a full ray per sample. Then shading, uneven lighting,
// noise and 8-bit quantisation. Optical blur is part of the pattern's evaluation (see
// render()).
//
// Frames: the sheet's own frame has the flat blank in its z = 0 plane; `Sheet::R, t` place
// it in the world (world = R sheet + t). Lengths in mm.

#include <limits>
#include <optional>
#include <vector>

#include "common/core/types.hpp"
#include "gsa/digitise/camera.hpp"
#include "gsa/digitise/image.hpp"

namespace sf::gsa::digitise::synth {

enum class SheetShape {
  kFlat,  // the blank: z = 0
  kDome,  // material radius r -> polar angle a r on a sphere of radius R (as gsa synth's dome)
  kBend,  // stretch (l1, l2) then bent about the sheet's y axis onto a cylinder of radius R
};

struct Sheet {
  SheetShape shape = SheetShape::kFlat;
  Vec2 centre = Vec2::Zero();                             // centre of the material rectangle (mm)
  double half_width = 77.5;                               // material half extent along X (mm)
  double half_height = 77.5;                              // along Y
  double trim = std::numeric_limits<double>::infinity();  // X + Y > trim is cut away
  double dome_radius = 150.0;                             // R (mm)
  double dome_stretch = 1.05;                             // meridional stretch R a
  double bend_radius = 100.0;                             // R (mm)
  double bend_stretch1 = 1.04;                            // along X (across the bend axis)
  double bend_stretch2 = 0.98;                            // along Y (the bend axis)
  Mat3 R = Mat3::Identity();                              // sheet frame -> world
  Vec3 t = Vec3::Zero();

  // The formed shape is placed so that the corners of the material rectangle sit at z = 0
  // and the part bulges toward +z.
  bool contains(const Vec2& m) const;  // m is on the part (inside the trimmed outline)
  Vec3 position(const Vec2& m) const;  // world position of material point m
  Vec3 normal(const Vec2& m) const;    // unit normal (world), the printed side
  // Exact principal stretches lambda1 >= lambda2 at material point m.
  std::pair<double, double> stretches(const Vec2& m) const;

  struct Hit {
    double distance = 0;  // along the unit ray
    Vec2 m;               // material coordinates
    Vec3 normal;          // world, of the printed side
    bool front = true;    // the printed side faces the ray's origin
  };
  // Nearest hit of the ray (origin o, unit direction d, world) on the part.
  std::optional<Hit> intersect(const Vec3& o, const Vec3& d) const;
};

enum class PatternKind {
  kDots,               // filled dots at (i, j) * pitch
  kLines,              // lines X = i pitch and Y = j pitch (junctions are the marks)
  kChessboard,         // inner corners (k, l) * pitch, k < cols, l < rows
  kCircles,            // symmetric circle grid, centres (k, l) * pitch
  kAsymmetricCircles,  // OpenCV's asymmetric grid, centres ((2k + l % 2), l) * pitch
};

struct Pattern {
  PatternKind kind = PatternKind::kDots;
  double pitch = 5.0;           // mm
  double dot_diameter = 2.0;    // dots, circle grids (mm)
  double line_width = 0.35;     // lines (mm)
  int i_min = -15, i_max = 15;  // dots / line junctions: index ranges
  int j_min = -15, j_max = 15;
  bool reference = true;             // dots: a bigger dot at (0, 0); lines: a dot in cell (0, 0)
  double reference_diameter = 2.83;  // dots: sqrt(2) x, twice the area; lines: the cell dot
  int cols = 9, rows = 6;            // chessboard inner corners / circle counts
  double ink = 0.08;                 // reflectance of the printed marks
  double paper = 0.85;               // reflectance of the sheet

  double reflectance(const Vec2& m) const;
  // The reflectance seen through a Gaussian blur: `blur` maps pixels to material
  // coordinates times the blur's standard deviation (sigma_px x d(material)/d(pixel)), so
  // the blur's covariance in material coordinates is blur blur^T. Each edge is smoothed
  // with an error function across it, crossings of two edges by the product rule; exact
  // for straight edges, and symmetric about every mark, so it moves no mark.
  double blurred_reflectance(const Vec2& m, const Mat2& blur) const;
  // A lower bound of the distance (mm) from m to the nearest place where the reflectance
  // changes (pixels farther from every edge than their footprint are not supersampled).
  double edge_distance(const Vec2& m) const;
  // Material coordinates of the marks (dots, junctions, corners, circle centres) in the
  // order a detector reports them for calibration targets (row by row), with their (i, j).
  struct Mark {
    int i, j;
    Vec2 m;
  };
  std::vector<Mark> marks() const;
};

// A flat opaque parallelogram in front of the part (a clamp, a fold of the sheet, a hand):
// points corner + a edge1 + b edge2, a, b in [0, 1] (world, mm).
struct Occluder {
  Vec3 corner, edge1, edge2;
  double grey = 0.55;  // reflectance
};

struct Lighting {
  Vec3 light = Vec3(0.3, -0.4, 1.0).normalized();  // toward the light (world)
  double ambient = 0.45, diffuse = 0.55;           // Lambertian shading of the sheet
  double gradient = 0.0;     // illumination falls by this fraction from the left to the right edge
  double vignetting = 0.0;   // fraction lost at the image corners (quadratic in the radius)
  double exposure = 1.0;     // grey level (0..1) of reflectance 1 under full light
  double background = 0.18;  // grey level where the part is not seen (dark cloth)
};

struct Scene {
  Sheet sheet;
  Pattern pattern;
  std::vector<Occluder> occluders;
  Lighting lighting;
};

struct Effects {
  int supersampling = 8;     // >= N^2 samples (a Fibonacci lattice) in pixels with an edge
  double blur_sigma = 0.0;   // optical blur (Gaussian PSF), pixels (0: none); see render()
  double noise_sigma = 0.0;  // additive Gaussian noise, grey levels of 1 (e.g. 2/255)
  unsigned seed = 1;
  int quantise_bits = 8;  // round to 8 or 16 bits (0: keep floats)
  int threads = 0;        // 0: the hardware's count
};

// Renders the scene as `camera` sees it (camera.width x camera.height pixels).
// The optical blur acts on the printed pattern BEFORE the pixels integrate it, as in a
// camera (a blur applied to the finished pixels would keep the pixels' bias toward
// integer positions of sharp edges, "pixel locking"); the part's outline and occluders
// stay sharp.
GreyImage render(const Camera& camera, const Scene& scene, const Effects& effects = {});

}  // namespace sf::gsa::digitise::synth
