#pragma once
// The measured region of a surface fit: where the marks are. The automatic mesh covers
// the marks' bounding rectangle with the empty elements dropped, so an element at the
// outline of a round blank or a waisted specimen reaches beyond the marks; drawn whole it
// shows surface (and strain) where nothing was measured, in stair steps.
//
// The region is the union of the triangles of a Delaunay triangulation of the marks (in
// the best-fit plane of the undeformed fit) less the slivers along the hull (triangles
// whose longest edge exceeds 2.5 x the median edge, as the triangle method drops them).
// Only elements with a free edge and their neighbours are tested: an element surrounded
// by others is taken as measured.

#include <vector>

#include "gsa/analysis.hpp"

namespace sf::gsa {

// For each cell of the subdiv x subdiv tessellation of each element (element-major, then
// xi2, then xi1, as surface_polymesh() orders its quads): does the cell's centre lie in
// the measured region? All true without marks to tell (fewer than three located marks).
std::vector<bool> measured_cells(const AnalysisResult& result, int subdiv);

}  // namespace sf::gsa
