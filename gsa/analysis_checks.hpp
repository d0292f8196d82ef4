#pragma once
// Checks on a finished analysis shared by `gsa analyse`, the Python module and the tests,
// so that every caller refuses or warns the same way (issue 20).
//
//   AnalysisResult r = analyse(grid, options);
//   if (!mesh_file.empty())
//     if (auto w = warn_uncovered_marks(r, mesh_file)) print("warning: " + *w);
//   refuse_if_nothing_analysed(r, grid, "surface");  // throws InputError

#include <optional>
#include <string>

#include "gsa/analysis.hpp"
#include "gsa/grid.hpp"

namespace sf::gsa {

// A run that analysed no mark fails instead of writing results that look complete: throws
// InputError "<first source>: no mark could be analysed (<count> <status>, ...)", with a hint
// for the triangles method (`method` as on the command line: "surface" or "triangles").
void refuse_if_nothing_analysed(const AnalysisResult& result, const GridData& grid, const std::string& method);

// A user mesh (`mesh_file`, --mesh) that does not cover the marks: those more than half a
// mark spacing off the undeformed fitted surface were fitted by extrapolation. Appends a
// warning counting them to result.warnings and returns it; nothing when every measured mark
// is covered (or the mark spacing is unknown).
std::optional<std::string> warn_uncovered_marks(AnalysisResult& result, const std::string& mesh_file);

}  // namespace sf::gsa
