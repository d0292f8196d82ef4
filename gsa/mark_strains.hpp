#pragma once
// Stage 4 of `gsa analyse`: strains at the marks from the two fitted surfaces at each
// mark's material point (docs/theory/strain.md, "Strains"; the formulas are in
// gsa/strain.hpp).

#include <limits>
#include <optional>
#include <vector>

#include "common/core/types.hpp"
#include "common/fe/surface_field.hpp"
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

// The two fitted surfaces over the same material coordinates (n_dofs x 3 parameters each).
struct SurfacePair {
  SurfacePair(const mesh::SurfaceMesh& mesh, const MatX& undeformed, const MatX& deformed);
  fe::SurfaceField undeformed, deformed;
};

// Strains at one material point between the two surfaces; with two fibre angles (degrees
// from the X axis on the undeformed sheet) also the fibre families and their shear angle.
// Marks are independent: the caller loops, writing each result where it belongs (a batch
// would allocate a second large array, and fresh memory costs 0.1 s per 16 MB on a
// loaded machine).
MarkStrain strain_at(const SurfacePair& surfaces, const MeshLocation& at, const std::vector<double>& fibre_angles);

}  // namespace sf::gsa
