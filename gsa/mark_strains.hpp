#pragma once
// Stage 4 of `gsa analyse`: strains at the marks from the two fitted surfaces at each
// mark's material point (docs/theory/strain.md, "Strains"; the formulas are in
// gsa/strain.hpp).

#include <limits>
#include <optional>
#include <vector>

#include "common/core/types.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "gsa/fit.hpp"
#include "gsa/strain.hpp"

namespace sf::gsa {

// One fibre family at a mark: its unit direction on the deformed surface and its stretch.
struct FibreResult {
  Vec3 direction = Vec3::Zero();
  double stretch = 0.0;
};

struct MarkStrain {
  std::optional<SurfaceStrain> strain;  // nothing where not asked for or the tangents are degenerate
  std::vector<FibreResult> fibres;      // one per fibre family (fibre mode)
  double shear_angle_deg = std::numeric_limits<double>::quiet_NaN();  // trellis shear of the two families
};

// Strains at `location` (m) between the surfaces `undeformed` and `deformed` (n_dofs x 3
// each) on `mesh`, for the marks with wanted[k]; with two fibre angles (degrees from the X
// axis on the undeformed sheet) also the fibre families and their shear angle.
std::vector<MarkStrain> strains_at_marks(const mesh::SurfaceMesh& mesh, const MatX& undeformed, const MatX& deformed,
                                         const std::vector<MeshLocation>& location, const std::vector<bool>& wanted,
                                         const std::vector<double>& fibre_angles);

}  // namespace sf::gsa
