// The stages of `gsa analyse` one by one (gsa/analysis.hpp): the progress each stage
// reports, one undeformed fit serving several deformed states, outlier flags with their
// reasons, readmission, and option errors that name the field for the library and the
// flag for the command line (gsa/command_options.hpp).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "gsa/analysis.hpp"
#include "gsa/command_options.hpp"
#include "gsa/deformed_fit.hpp"
#include "gsa/output.hpp"
#include "gsa/synthetic.hpp"
#include "gsa/undeformed_fit.hpp"

namespace sf::gsa {
namespace {

using ::testing::ElementsAre;
using ::testing::StartsWith;

// Strains a bicubic mesh reproduces exactly (homogeneous deformations of a flat sheet):
// measured ~1e-14; room for solver round-off.
constexpr double kExactStrain = 1e-9;

GridData grid_of(const std::string& name, int n = 11, int outliers = 0) {
  SyntheticGridOptions go;
  go.n = n;
  go.outliers = outliers;
  return make_synthetic_grid(synthetic_case(name), go);
}

TEST(GsaStages, ProgressHearsEachStageInOrderWithTheMesh) {
  const GridData grid = grid_of("dome");
  std::vector<AnalysisStage> heard;
  std::string layout;
  auto progress = [&](const StageStart& s) {
    heard.push_back(s.stage);
    if (s.stage == AnalysisStage::kFrameAndMesh) {
      EXPECT_EQ(s.mesh, nullptr);
    }
    if (s.stage == AnalysisStage::kUndeformedFit) {
      ASSERT_NE(s.mesh, nullptr);
      layout = s.mesh->layout;
      EXPECT_GT(s.mesh->mesh.n_elements(), 0);
    }
  };
  const AnalysisResult r = analyse(grid, {}, progress);
  EXPECT_THAT(heard,
              ElementsAre(AnalysisStage::kFrameAndMesh, AnalysisStage::kOutliers, AnalysisStage::kUndeformedFit,
                          AnalysisStage::kDeformedFit, AnalysisStage::kSmoothingChoice, AnalysisStage::kStrains));
  EXPECT_EQ(layout, r.mesh_layout);
  // Explicit weights: no smoothing is chosen.
  heard.clear();
  AnalyseOptions o;
  o.smoothing.gamma = 1.0;
  analyse(grid, o, progress);
  EXPECT_THAT(heard, ElementsAre(AnalysisStage::kFrameAndMesh, AnalysisStage::kOutliers, AnalysisStage::kUndeformedFit,
                                 AnalysisStage::kDeformedFit, AnalysisStage::kStrains));
}

// Stage series: the undeformed fit of the marks once, then two deformed states of the
// same marks (a homogeneous stretch and the same stretch moved rigidly), each fitted
// against it; both give the exact stretches.
TEST(GsaStages, OneUndeformedFitServesSeveralDeformedStates) {
  GridData grid = grid_of("stretch");
  const FitMarks marks = fit_marks(grid);
  const FrameAndMesh setup = build_frame_and_mesh(grid, marks, {});
  UndeformedFitOptions uo;
  uo.smoothing.gamma = 1e-6;
  const UndeformedFit und = fit_undeformed(setup, marks, uo);
  ASSERT_TRUE(und.flags.empty());
  const Mat3 turn = Eigen::AngleAxisd(0.4, Vec3(0, 1, 1).normalized()).toRotationMatrix();
  const std::vector<Mat3> states = {Vec3(1.1, 1.05, 1).asDiagonal().toDenseMatrix(),
                                    turn * Vec3(0.95, 1.2, 1).asDiagonal().toDenseMatrix()};
  const std::vector<std::pair<double, double>> stretches = {{1.1, 1.05}, {1.2, 0.95}};
  for (std::size_t s = 0; s < states.size(); ++s) {
    SCOPED_TRACE("state " + std::to_string(s));
    for (Index p = 0; p < grid.n_points(); ++p)
      grid.deformed.row(p) = (states[s] * grid.undeformed.row(p).transpose() + Vec3(3, -2, 1)).transpose();
    const DeformedMarks data = deformed_marks(grid, marks, und);
    DeformedProblem problem(setup, marks, und, data);
    const DeformedFit fit = fit_deformed(problem, explicit_penalty(uo.smoothing), {});
    EXPECT_TRUE(fit.flags.empty());
    const SurfacePair surfaces(setup.mesh, und.parameters, fit.fit.parameters);
    for (std::size_t k = 0; k < und.location.size(); ++k) {
      const MarkStrain m = strain_at(surfaces, und.location[k], {});
      ASSERT_TRUE(m.strain) << "mark " << k;
      EXPECT_NEAR(m.strain->lambda1, stretches[s].first, kExactStrain) << "mark " << k;
      EXPECT_NEAR(m.strain->lambda2, stretches[s].second, kExactStrain) << "mark " << k;
    }
  }
}

// Two marks digitised 2 mm off: the neighbour check flags exactly them, each flag with its
// reason and numbers; they take no part in the deformed fit, are not readmitted (the
// final surface passes far from them), and still get the fitted surfaces' strain.
TEST(GsaStages, OutlierFlagsCarryReasonDeviationThresholdAndNoise) {
  const GridData grid = grid_of("dome", 21, 2), clean = grid_of("dome", 21, 0);
  std::vector<Index> offset;  // the marks moved 2 mm
  for (Index p = 0; p < grid.n_points(); ++p)
    if ((grid.deformed.row(p) - clean.deformed.row(p)).norm() > 1.0) offset.push_back(p);
  ASSERT_EQ(offset.size(), 2u);
  const AnalyseOptions o;
  const FitMarks marks = fit_marks(grid);
  const FrameAndMesh setup = build_frame_and_mesh(grid, marks, o.mesh);
  Points3 deformed(marks.size(), 3);
  for (Index k = 0; k < marks.size(); ++k)
    deformed.row(k) = grid.deformed.row(marks.point[static_cast<std::size_t>(k)]);
  MarkOutliers found = find_outliers(marks, deformed, setup.mark_spacing, o.outliers);
  EXPECT_TRUE(found.undeformed.empty());
  ASSERT_EQ(found.deformed.size(), 2u);
  for (const OutlierFlag& f : found.deformed) {
    EXPECT_EQ(f.reason, OutlierReason::kDeformedOffNeighbours);
    EXPECT_GT(f.deviation, f.threshold);
    EXPECT_NEAR(f.threshold, std::max(o.outliers.sigma * f.noise, o.outliers.floor * setup.mark_spacing), 1e-12);
    EXPECT_GT(f.deviation, 1.0);  // about the 2 mm offset
    EXPECT_NE(describe(f, o.outliers.sigma, "mm").find("threshold"), std::string::npos);
  }
  const UndeformedFit und =
      fit_undeformed(setup, marks, {o.smoothing, found.undeformed, o.max_projection_iterations, {}});
  const DeformedMarks data = deformed_marks(grid, marks, und);
  DeformedProblem problem(setup, marks, und, data);
  const double d = setup.mark_spacing;
  DeformedFit fit = fit_deformed(problem, penalty_for_noise(o.smoothing, und.noise_estimate, d), found.deformed);
  for (const OutlierFlag& f : fit.flags) EXPECT_EQ(problem.weight()[f.mark], 0.0);
  refit_deformed(problem, fit, choose_smoothing_gcv(problem, o.smoothing, d));
  readmit_deformed(problem, fit);
  std::vector<Index> kept;
  for (const OutlierFlag& f : fit.flags) kept.push_back(marks.point[static_cast<std::size_t>(f.mark)]);
  std::sort(kept.begin(), kept.end());
  EXPECT_EQ(kept, offset);
  // The whole analysis reports the same two marks, and gives them strains.
  const AnalysisResult r = analyse(grid, o);
  std::vector<Index> flagged;
  for (Index p = 0; p < grid.n_points(); ++p)
    if (r.points[p].status == kStatusOutlierDeformed) {
      flagged.push_back(p);
      EXPECT_TRUE(r.points[p].strain.has_value());
      ASSERT_TRUE(r.points[p].flag.has_value());
    }
  EXPECT_EQ(flagged, offset);
}

TEST(GsaStages, ReadmissionTakesBackTheMarksTheSurfacePassesWithinTheirThreshold) {
  VecX residual(4);
  residual << 0.1, 5.0, 0.3, 0.9;
  std::vector<OutlierFlag> flags = {{1, OutlierReason::kDeformedOffNeighbours, 5.2, 1.0, 0.2},
                                    {3, OutlierReason::kDeformedOffNeighbours, 1.5, 1.0, 0.2}};
  const std::vector<OutlierFlag> back = take_readmitted(flags, residual);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].mark, 3);
  ASSERT_EQ(flags.size(), 1u);
  EXPECT_EQ(flags[0].mark, 1);
}

// Every bad value the library can meet names its field; the command line names the flag
// that sets the field.
TEST(GsaStages, OptionErrorsNameTheFieldAndOnTheCommandLineTheFlag) {
  struct Bad {
    std::string field, flag;
    std::function<void(AnalyseOptions&)> set;
  };
  const std::vector<Bad> bad = {
      {"mesh.elements1", "--elements", [](AnalyseOptions& o) { o.mesh.elements1 = -1; }},
      {"mesh.elements2", "--elements", [](AnalyseOptions& o) { o.mesh.elements2 = -2; }},
      {"mesh.file", "--mesh", [](AnalyseOptions& o) { o.mesh.file = "m.json", o.mesh.elements1 = 3; }},
      {"smoothing.alpha", "--alpha", [](AnalyseOptions& o) { o.smoothing.alpha = -1; }},
      {"smoothing.beta", "--beta", [](AnalyseOptions& o) { o.smoothing.beta = -1; }},
      {"smoothing.gamma", "--gamma", [](AnalyseOptions& o) { o.smoothing.gamma = std::nan(""); }},
      {"smoothing.delta", "--delta", [](AnalyseOptions& o) { o.smoothing.delta = -1; }},
      {"smoothing.scale", "--smoothing-scale", [](AnalyseOptions& o) { o.smoothing.scale = 0; }},
      {"outliers.sigma", "--outlier-sigma", [](AnalyseOptions& o) { o.outliers.sigma = -3; }},
      {"fibre_angles", "--fibres", [](AnalyseOptions& o) { o.fibre_angles = {0}; }},
      {"fibre_angles", "--fibres",
       [](AnalyseOptions& o) {
         o.fibre_angles = {0, 90, 45};
       }},
  };
  const GridData grid = grid_of("stretch", 5);
  for (const Bad& b : bad) {
    SCOPED_TRACE(b.field);
    AnalyseOptions o;
    b.set(o);
    try {
      analyse(grid, o);
      ADD_FAILURE() << "no error";
    } catch (const OptionError& e) {
      EXPECT_EQ(e.field(), b.field);
      EXPECT_THAT(std::string(e.what()), StartsWith(b.field + ": "));
      EXPECT_EQ(flag_of_field(e.field()), b.flag);
    }
  }
  OutputOptions out;
  out.sample = 51;
  try {
    out.validate();
    ADD_FAILURE() << "no error";
  } catch (const OptionError& e) {
    EXPECT_EQ(flag_of_field(e.field()), "--sample");
  }
  // Through the command layer the message starts with the flag.
  AnalyseFlags flags;
  flags.smoothing_scale = 0;
  try {
    analyse_options(flags);
    ADD_FAILURE() << "no error";
  } catch (const UsageError& e) {
    EXPECT_THAT(std::string(e.what()), StartsWith("--smoothing-scale: must be a finite number > 0"));
  }
  flags = AnalyseFlags{};
  flags.sample = -1;
  EXPECT_THROW(output_options(flags), UsageError);
}

}  // namespace
}  // namespace sf::gsa
