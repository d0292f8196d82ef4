#pragma once
// `gsa analyse`: surface-fit grid strain analysis (BRIEF.md §1) and the classical
// per-triangle method, from a GridData to per-point strains and fitted surfaces.
//
// The surface method runs as named stages, each a function with its own inputs and
// result (docs/theory/strain.md):
//
//   stage              function                     result            header
//   frame and mesh     fit_marks, build_frame_and_mesh  FrameAndMesh  gsa/frame_mesh.hpp
//   undeformed fit     fit_undeformed               UndeformedFit     gsa/undeformed_fit.hpp
//   deformed fit       fit_deformed, refit_deformed DeformedFit       gsa/deformed_fit.hpp
//   outliers           find_outliers, take_readmitted  MarkOutliers    gsa/outliers.hpp
//   noise model        undeformed_noise, deformed_noise NoiseEstimate  gsa/noise_estimate.hpp
//   smoothing choice   choose_smoothing_noise_model (or _gcv)  SmoothingChoice  gsa/smoothing.hpp
//   local smoothing    relax_smoothing              LocalSmoothing    gsa/local_smoothing.hpp
//   strains            strain_at (per mark)         MarkStrain        gsa/mark_strains.hpp
//
// analyse() runs them in that order and gathers an AnalysisResult. It never prints:
// progress goes to a callback as each stage starts.

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "gsa/fit.hpp"
#include "gsa/frame_mesh.hpp"
#include "gsa/grid.hpp"
#include "gsa/mark_strains.hpp"
#include "gsa/noise_model.hpp"
#include "gsa/option_error.hpp"
#include "gsa/outliers.hpp"
#include "gsa/plane.hpp"
#include "gsa/smoothing.hpp"
#include "gsa/strain.hpp"
#include "gsa/undeformed_fit.hpp"
#include "gsa/weights.hpp"

namespace sf::gsa {

enum class Method { kSurface, kTriangles };

// A deformed smoothing chosen elsewhere and taken as it is: a stage series chooses it once,
// on one stage, for every stage (gsa/series.hpp).
struct FixedSmoothing {
  SmoothingChoice choice;          // penalty, passes, criterion and its optimum
  std::vector<double> multiplier;  // local smoothing: per element (empty: 1 everywhere)
  NoiseEstimate noise;             // the deformed noise it was chosen with (reported)
};

struct AnalyseOptions {
  Method method = Method::kSurface;
  MeshOptions mesh;                   // frame and mesh
  SmoothingOptions smoothing;         // both fits
  OutlierOptions outliers;            // both fits
  int max_projection_iterations = 5;  // undeformed fit
  std::vector<double> fibre_angles;   // none, or two: degrees from the X axis on the undeformed sheet
  // Fit weights w = (sigma_ref / sigma)^2 from the input's per-point sigma (gsa/weights.hpp);
  // false: every mark weight 1. No effect when the input has no sigma.
  bool sigma_weights = true;
  // Automatic smoothing only: the deformed fit takes this choice instead of choosing one.
  std::optional<FixedSmoothing> fixed_smoothing;

  // Throws OptionError naming the field (e.g. "smoothing.scale") for a value out of range.
  void validate() const;
};

// Per-point status words written to strains.csv.
inline constexpr const char* kStatusOk = "ok";
inline constexpr const char* kStatusMissingUndeformed = "missing_undeformed";
inline constexpr const char* kStatusMissingDeformed = "missing_deformed";
// The measuring system marked the point invalid in a state (GridData::not_measured).
inline constexpr const char* kStatusNotMeasured = "not_measured";
inline constexpr const char* kStatusOutlierUndeformed = "outlier_undeformed";
inline constexpr const char* kStatusOutlierDeformed = "outlier_deformed";
inline constexpr const char* kStatusDegenerate = "degenerate";
inline constexpr const char* kStatusNoTriangle = "no_triangle";

struct PointResult {
  std::string status = kStatusOk;
  Index element = -1;
  Vec2 xi = Vec2::Zero();
  std::optional<SurfaceStrain> strain;
  double residual = std::numeric_limits<double>::quiet_NaN();             // deformed fit
  double residual_undeformed = std::numeric_limits<double>::quiet_NaN();  // undeformed fit
  std::vector<FibreResult> fibres;                                        // one per fibre family
  double shear_angle_deg = std::numeric_limits<double>::quiet_NaN();      // first two families
  std::optional<OutlierFlag> flag;  // why the point was flagged (outlier statuses), with its numbers
};

// Wall seconds per stage. `fit` is the least-squares fits alone; the blunder check
// (`outliers`), the noise estimates (`noise`) and the smoothing choice with its local
// relaxation (`choice`) are timed apart.
struct StageTimes {
  double read = 0, mesh = 0, project = 0, fit = 0, strain = 0, write = 0;
  double outliers = 0, noise = 0, choice = 0;
};

struct AnalysisResult {
  Method method = Method::kSurface;
  std::vector<PointResult> points;   // one per grid point, in grid order
  std::vector<double> fibre_angles;  // as analysed (degrees)
  double outlier_sigma = 0.0;        // the outlier threshold used (surface method)
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
  double noise_estimate = 0.0;  // estimated digitisation noise (units), per coordinate
  double mark_spacing = 0.0;    // mean spacing of marks (units)
  double gauge_length = 0.0;    // effective smoothing length (units)
  double log10_delta_optimum =
      std::numeric_limits<double>::quiet_NaN();  // criterion's optimum, log10(delta / spacing^6)
  int fit_passes = 1;                            // passes of the deformed fit (iterated Tikhonov, gsa/fit.hpp)
  std::string smoothing_criterion;               // "GCV", "Cp" (noise model) or empty (explicit weights)
  double smoothing_criterion_value = std::numeric_limits<double>::quiet_NaN();
  double rms_undeformed = 0, max_undeformed = 0, rms_deformed = 0, max_deformed = 0;
  int projection_iterations = 0;
  Index n_triangles = 0;  // triangles method
  StageTimes times;
  std::vector<std::string> warnings;
  // Noise-model smoothing (gsa/noise_estimate.hpp): the undeformed estimate (correlation
  // length) and the deformed data's; all zero with another rule.
  NoiseEstimate noise_undeformed, noise;
  // Exact blank (the undeformed estimate zero: nominal positions): the estimate from the
  // displacement's local fits (displacement_noise, gsa/noise_model.hpp); its length is the
  // deformed estimate's where it is confirmed (correlation_length > 0). Zero otherwise.
  NoiseEstimate noise_displacement;
  std::vector<double> element_multiplier;  // local smoothing: penalty multiplier per element (1: global weight)
  Index relaxed_elements = 0;              // elements with a multiplier below 1
  double local_gauge_length = 0.0;         // gauge length in the relaxed elements (units; 0: none)
  // Automatic mesh refined at a localised feature narrower than an element (a neck):
  // rounds of refinement (0: none) and the smallest element then (units).
  int refinement_rounds = 0;
  double smallest_element = 0.0;
  double noise_outliers_undeformed = 0.0, noise_outliers_deformed = 0.0;  // noise levels of the outlier checks (units)
  double noise_outliers_deformed_axis = 0.0, noise_outliers_deformed_across = 0.0;  // its two levels: along the noisiest axis, across it (units)
  SigmaWeights weights_undeformed, weights_deformed;  // fit weights from the sigmas (used = false: all 1)
};

enum class AnalysisStage { kFrameAndMesh, kOutliers, kUndeformedFit, kDeformedFit, kSmoothingChoice, kStrains };

// What the progress callback hears as each stage of the surface method starts.
struct StageStart {
  AnalysisStage stage = AnalysisStage::kFrameAndMesh;
  const FrameAndMesh* mesh = nullptr;  // from kUndeformedFit on: the frame and mesh of the fits
};
using ProgressCallback = std::function<void(const StageStart&)>;

// Validates the options, then runs the method. Throws sf::InputError naming the file for
// grids that cannot be analysed (too few marks, marks on a line, a singular fit).
AnalysisResult analyse(const GridData& grid, const AnalyseOptions& options, const ProgressCallback& progress = {});

// The surface method in two parts, for a stage series (gsa/series.hpp: one undeformed
// state, many deformed ones). analyse_undeformed() runs the stages that do not depend on
// the deformed state (frame and mesh, undeformed outliers, undeformed fit, undeformed
// noise); analyse_deformed() runs the rest for one deformed state of the same marks (the
// grid's undeformed positions must be those analyse_undeformed() had). analyse() is the
// two in a row; analyse_deformed()'s times cover its own stages only.
struct UndeformedStages {
  FitMarks marks;
  FrameAndMesh setup;
  MarkOutliers outliers;  // the undeformed flags (deformed: empty)
  SigmaWeights weights;   // of the undeformed positions
  UndeformedFit fit;
  NoiseEstimate noise;  // of the undeformed fit (noise-model rule; else zero)
  double mesh_seconds = 0.0;
  double outliers_seconds = 0.0;  // the undeformed blunder check
  double noise_seconds = 0.0;     // the undeformed noise estimate
};
UndeformedStages analyse_undeformed(const GridData& grid, const AnalyseOptions& options,
                                    const ProgressCallback& progress = {});
AnalysisResult analyse_deformed(const UndeformedStages& undeformed, const GridData& grid, const AnalyseOptions& options,
                                const ProgressCallback& progress = {});

// The classical method: triangles of neighbouring marks (grid i, j when every
// point has them, else a Delaunay triangulation in the best-fit plane), homogeneous
// strain per triangle, right Cauchy-Green tensors averaged to the marks.
AnalysisResult analyse_triangles(const GridData& grid, const AnalyseOptions& options);

}  // namespace sf::gsa
