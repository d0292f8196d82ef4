#pragma once
// Stage 1 of `gsa analyse` (surface method): the marks that take part, their frame (the
// best-fit plane) and the mesh both surfaces are fitted on (docs/theory/strain.md, "Frame
// and mesh").
//
//   FitMarks marks = fit_marks(grid);                       // marks with an undeformed position
//   FrameAndMesh setup = build_frame_and_mesh(grid, marks, options.mesh);
//
// The automatic mesh is a structured n1 x n2 bicubic Hermite rectangle over the marks'
// bounding rectangle in the plane, its size from the number of marks, with the elements
// that hold no mark dropped. A user mesh (MeshOptions::file, gsa/mesh_file.hpp) is taken
// as it is and the marks are located on it by projection.

#include <string>
#include <vector>

#include "common/core/types.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "gsa/fit.hpp"
#include "gsa/grid.hpp"
#include "gsa/plane.hpp"

namespace sf::gsa {

// The marks of the surface fit: those with an undeformed position, in grid order.
struct FitMarks {
  std::string source;        // the grid's (first) file, for messages
  std::vector<Index> point;  // m: the grid index of each mark
  Points3 undeformed;        // m x 3: their undeformed positions (units of the grid)
  Index size() const { return static_cast<Index>(point.size()); }
};
// Throws sf::InputError naming the file when fewer than 6 marks have an undeformed position.
FitMarks fit_marks(const GridData& grid);

struct MeshOptions {
  int elements1 = 0, elements2 = 0;  // automatic mesh of n1 x n2 elements; 0 = from the number of marks
  std::string file;                  // the user's own mesh instead (JSON, gsa/mesh_file.hpp)
  // Automatic mesh only: element boundaries as fractions of the marks' extent along each
  // axis (n + 1 ascending values from 0 to 1), e.g. finer where a neck is
  // (gsa/analysis.cpp, "refinement"); empty: uniform.
  std::vector<double> breaks1, breaks2;
};

struct FrameAndMesh {
  PlaneFrame frame;                      // best-fit plane of the undeformed marks
  mesh::SurfaceMesh mesh;                // the fitting mesh, in the grid's units
  std::vector<MeshLocation> start;       // m: each mark's starting location on it
  int elements1 = 0, elements2 = 0;      // automatic mesh: its size before empty elements were dropped
  std::vector<double> breaks1, breaks2;  // automatic mesh: its element boundaries (fractions, n + 1 each)
  Eigen::MatrixX2d plane;                // automatic mesh: each mark's in-plane coordinates (frame axes)
  Eigen::Vector2d plane_low = Eigen::Vector2d::Zero(), plane_length = Eigen::Vector2d::Zero();  // the meshed box
  std::string layout;                                                                           // "7x7", or "from FILE"
  double mark_spacing = 0.0;  // d = sqrt(mesh area / marks), units
  PenaltyMatrices penalties;  // the smoothing penalties of `mesh`, assembled once
};
// Throws sf::InputError naming the file when the marks lie on a line, and naming the mark
// (file:line) when it cannot be located on a user mesh. Fit systems built on the result
// point into it: keep it in place while they live.
FrameAndMesh build_frame_and_mesh(const GridData& grid, const FitMarks& marks, const MeshOptions& options);

}  // namespace sf::gsa
