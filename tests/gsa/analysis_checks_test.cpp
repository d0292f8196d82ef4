// The checks on a finished analysis that `gsa analyse`, the Python module and these tests
// share (gsa/analysis_checks.hpp, issue 20).
#include "gsa/analysis_checks.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/core/error.hpp"

namespace sf::gsa {
namespace {

// Four marks two grid steps apart (i, j = 0 or 2): the triangles method finds no triangle.
GridData four_marks_no_triangle() {
  GridData g;
  g.sources = {"no_triangles.csv"};
  g.ids = {"a", "b", "c", "d"};
  g.undeformed.resize(4, 3);
  g.deformed.resize(4, 3);
  g.undeformed << 0, 0, 0, 10, 0, 0, 0, 10, 0, 10, 10, 0;
  g.deformed << 0, 0, 0, 10.1, 0, 0, 0, 10.1, 0, 10.1, 10.1, 0;
  g.has_ij = true;
  g.i = {0, 2, 0, 2};
  g.j = {0, 0, 2, 2};
  return g;
}

TEST(GsaAnalysisChecks, NothingAnalysedIsRefusedWithTheCountsAndTheHint) {
  const GridData g = four_marks_no_triangle();
  AnalyseOptions o;
  o.method = Method::kTriangles;
  const AnalysisResult r = analyse(g, o);
  try {
    refuse_if_nothing_analysed(r, g, "triangles");
    FAIL() << "no mark was analysed, and nothing was refused";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "no_triangles.csv: no mark could be analysed (4 no_triangle); the triangles method needs neighbouring "
              "marks (grid indices i, j one apart, or marks spread over an area, not along a line)");
  }
}

TEST(GsaAnalysisChecks, OneAnalysedMarkIsEnough) {
  const GridData g = four_marks_no_triangle();
  AnalysisResult r;
  r.points.resize(4);
  for (auto& p : r.points) p.status = kStatusNoTriangle;
  r.points[2].status = kStatusOk;
  r.points[2].strain.emplace();  // analysed (the values do not matter here)
  EXPECT_NO_THROW(refuse_if_nothing_analysed(r, g, "triangles"));
  r.points.clear();  // no marks at all
  GridData none;
  EXPECT_THROW(
      {
        try {
          refuse_if_nothing_analysed(r, none, "surface");
        } catch (const InputError& e) {
          EXPECT_EQ(std::string(e.what()), "input: no mark could be analysed (no marks)");
          throw;
        }
      },
      InputError);
}

TEST(GsaAnalysisChecks, MarksOffTheUserMeshAreCountedInOneWarning) {
  AnalysisResult r;
  r.mark_spacing = 4.0;
  r.points.resize(4);
  r.points[0].residual_undeformed = 0.1;
  r.points[1].residual_undeformed = 2.5;  // more than half a spacing off
  r.points[2].residual_undeformed = 1.9;
  // points[3]: not measured (NaN), not counted
  const auto w = warn_uncovered_marks(r, "mesh.json");
  ASSERT_TRUE(w.has_value());
  EXPECT_EQ(*w,
            "1 of 3 marks lie more than half a mark spacing off the surface fitted on the mesh of mesh.json: the mesh "
            "does not cover them and their strains are unreliable; give a mesh that covers every mark");
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0], *w);
  // Covered (and an unknown spacing): no warning.
  r.points[1].residual_undeformed = 1.0;
  EXPECT_FALSE(warn_uncovered_marks(r, "mesh.json").has_value());
  r.points[1].residual_undeformed = 2.5;
  r.mark_spacing = 0.0;
  EXPECT_FALSE(warn_uncovered_marks(r, "mesh.json").has_value());
  EXPECT_EQ(r.warnings.size(), 1u);
}

}  // namespace
}  // namespace sf::gsa
