#include "gsa/analysis_checks.hpp"

#include <cmath>
#include <map>

#include "common/core/error.hpp"

namespace sf::gsa {

void refuse_if_nothing_analysed(const AnalysisResult& result, const GridData& grid, const std::string& method) {
  std::map<std::string, Index> by_status;
  for (const auto& p : result.points) {
    if (p.strain) return;
    ++by_status[p.status];
  }
  std::string counts;
  for (const auto& [status, n] : by_status) counts += (counts.empty() ? "" : ", ") + std::to_string(n) + " " + status;
  std::string hint;
  if (method == "triangles")
    hint =
        "; the triangles method needs neighbouring marks (grid indices i, j one apart, or marks spread over an "
        "area, not along a line)";
  throw InputError((grid.sources.empty() ? std::string("input") : grid.sources.front()) +
                   ": no mark could be analysed (" + (counts.empty() ? "no marks" : counts) + ")" + hint);
}

std::optional<std::string> warn_uncovered_marks(AnalysisResult& result, const std::string& mesh_file) {
  if (!(result.mark_spacing > 0.0)) return std::nullopt;
  Index outside = 0, measured = 0;
  for (const auto& p : result.points) {
    if (std::isnan(p.residual_undeformed)) continue;
    ++measured;
    if (p.residual_undeformed > 0.5 * result.mark_spacing) ++outside;
  }
  if (outside == 0) return std::nullopt;
  const std::string w = std::to_string(outside) + " of " + std::to_string(measured) + " marks lie more than half a " +
                        "mark spacing off the surface fitted on the mesh of " + mesh_file +
                        ": the mesh does not cover them and their strains are unreliable; give a mesh that covers "
                        "every mark";
  result.warnings.push_back(w);
  return w;
}

}  // namespace sf::gsa
