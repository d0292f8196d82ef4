#pragma once
// `gsa analyse`: surface-fit grid strain analysis (BRIEF.md §1) and the classical
// per-triangle method, from a GridData to per-point strains and fitted surfaces.
//
// Pipeline (surface method):
//  1. frame: best-fit plane of the undeformed marks (PCA); a1 = longest in-plane axis;
//  2. mesh: a structured bicubic Hermite mesh over the marks' bounding rectangle in
//     that plane, element count from the number of marks per element (or given);
//     elements holding no mark are dropped;
//  3. undeformed fit, alternating with nearest-point projection of the marks until
//     their xi settle; outliers (residual >> robust noise level) are flagged and left out;
//  4. deformed fit on the same mesh and xi, smoothing the displacement;
//  5. strains from the two surfaces' metrics at every mark (and on a sampling).

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "gsa/fit.hpp"
#include "gsa/grid.hpp"
#include "gsa/plane.hpp"
#include "gsa/strain.hpp"

namespace sf::gsa {

enum class Method { kSurface, kTriangles };
enum class PenaltyKind { kThirdOrder, kSobolev, kJumps };


struct AnalyseOptions {
  Method method = Method::kSurface;
  PenaltyKind penalty = PenaltyKind::kJumps;
  int elements1 = 0, elements2 = 0;  // 0 = automatic (--elements NxM)
  std::string mesh_file;              // --mesh FILE: the user's own mesh (gsa/mesh_file.hpp)
  std::optional<double> alpha, beta, gamma, delta;  // unset = automatic
  std::vector<double> fibre_angles;          // degrees from the X axis on the undeformed sheet
  std::string units = "mm";
  double smoothing_scale = 1.0;  // multiplies the automatic smoothing weights
  double outlier_sigma = 6.0;   // residual threshold in robust noise sigmas
  int max_projection_iterations = 5;
  int sample = 0;               // >0: also sample fields on sample x sample points per element
  bool quiet = true;
  void validate() const;
};

// Per-point status words written to strains.csv.
inline constexpr const char* kStatusOk = "ok";
inline constexpr const char* kStatusMissingUndeformed = "missing_undeformed";
inline constexpr const char* kStatusMissingDeformed = "missing_deformed";
inline constexpr const char* kStatusOutlierUndeformed = "outlier_undeformed";
inline constexpr const char* kStatusOutlierDeformed = "outlier_deformed";
inline constexpr const char* kStatusDegenerate = "degenerate";
inline constexpr const char* kStatusNoTriangle = "no_triangle";

struct FibreResult {
  Vec3 direction = Vec3::Zero();
  double stretch = 0.0;
};

struct PointResult {
  std::string status = kStatusOk;
  Index element = -1;
  Vec2 xi = Vec2::Zero();
  std::optional<SurfaceStrain> strain;
  double residual = std::numeric_limits<double>::quiet_NaN();             // deformed fit
  double residual_undeformed = std::numeric_limits<double>::quiet_NaN();  // undeformed fit
  std::vector<FibreResult> fibres;  // one per fibre family
  double shear_angle_deg = std::numeric_limits<double>::quiet_NaN();  // first two families
};

struct StageTimes {
  double read = 0, mesh = 0, project = 0, fit = 0, strain = 0, write = 0;
};

struct AnalysisResult {
  Method method = Method::kSurface;
  std::vector<PointResult> points;
  // Surface method only:
  mesh::SurfaceMesh mesh;
  MatX undeformed_parameters, deformed_parameters;  // n_dofs x 3
  Vec3 centroid = Vec3::Zero(), axis1 = Vec3::UnitX(), axis2 = Vec3::UnitY();
  RigidMotion rigid;  // best-fit rigid motion of the marks, undeformed -> deformed
  int elements1 = 0, elements2 = 0;
  std::string mesh_layout;  // "7x7" (automatic rectangle) or "from FILE"
  Penalty penalty_undeformed, penalty_deformed;
  PenaltyKind penalty_kind = PenaltyKind::kThirdOrder;
  bool smoothing_automatic = false;
  double noise_estimate = 0.0;   // estimated digitisation noise (units), per coordinate
  double mark_spacing = 0.0;     // mean spacing of marks (units)
  double gauge_length = 0.0;     // effective smoothing length (units)
  double gcv_log10_delta = std::numeric_limits<double>::quiet_NaN();  // GCV optimum, log10(delta / spacing^6)
  double rms_undeformed = 0, max_undeformed = 0, rms_deformed = 0, max_deformed = 0;
  int projection_iterations = 0;
  Index n_triangles = 0;  // triangles method
  StageTimes times;
  std::vector<std::string> warnings;
};

AnalysisResult analyse(const GridData& grid, const AnalyseOptions& options);

// The classical method: triangles of neighbouring marks (grid i, j when every
// point has them, else a Delaunay triangulation in the best-fit plane), homogeneous
// strain per triangle, right Cauchy-Green tensors averaged to the marks.
AnalysisResult analyse_triangles(const GridData& grid, const AnalyseOptions& options);

}  // namespace sf::gsa
