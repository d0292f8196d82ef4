#include "gsa/mark_strains.hpp"

namespace sf::gsa {

SurfacePair::SurfacePair(const mesh::SurfaceMesh& mesh, const MatX& undeformed_parameters,
                         const MatX& deformed_parameters)
    : undeformed(mesh, undeformed_parameters), deformed(mesh, deformed_parameters) {}

MarkStrain strain_at(const SurfacePair& surfaces, const MeshLocation& at, const std::vector<double>& fibre_angles) {
  const auto b = basis::BicubicHermite::evaluate(at.xi, basis::kValues | basis::kFirst);
  const fe::SurfacePoint pu = surfaces.undeformed.evaluate3(at.element, b);
  const fe::SurfacePoint pd = surfaces.deformed.evaluate3(at.element, b);
  MarkStrain ms;
  ms.strain = surface_strain(pu.dx, pd.dx);
  if (!ms.strain || fibre_angles.size() != 2) return ms;
  const FibrePair fp = fibre_pair(pu.dx, pd.dx, fibre_angles[0], fibre_angles[1]);
  for (const auto& fs : fp.state)
    ms.fibres.push_back(fs ? FibreResult{fs->direction_deformed, fs->stretch} : FibreResult{});
  ms.shear_angle_deg = fp.shear_angle_deg;
  return ms;
}

}  // namespace sf::gsa
