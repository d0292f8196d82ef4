#include "gsa/mark_strains.hpp"

#include "common/fe/surface_field.hpp"

namespace sf::gsa {

std::vector<MarkStrain> strains_at_marks(const mesh::SurfaceMesh& mesh, const MatX& undeformed, const MatX& deformed,
                                         const std::vector<MeshLocation>& location, const std::vector<bool>& wanted,
                                         const std::vector<double>& fibre_angles) {
  const fe::SurfaceField fu(mesh, undeformed), fd(mesh, deformed);
  std::vector<MarkStrain> out(location.size());
  for (std::size_t k = 0; k < location.size(); ++k) {
    if (!wanted[k]) continue;
    const MeshLocation& loc = location[k];
    const auto b = basis::BicubicHermite::evaluate(loc.xi, basis::kValues | basis::kFirst);
    const fe::SurfacePoint pu = fu.evaluate3(loc.element, b), pd = fd.evaluate3(loc.element, b);
    MarkStrain& ms = out[k];
    ms.strain = surface_strain(pu.dx, pd.dx);
    if (!ms.strain || fibre_angles.size() != 2) continue;
    const FibrePair fp = fibre_pair(pu.dx, pd.dx, fibre_angles[0], fibre_angles[1]);
    for (const auto& fs : fp.state)
      ms.fibres.push_back(fs ? FibreResult{fs->direction_deformed, fs->stretch} : FibreResult{});
    ms.shear_angle_deg = fp.shear_angle_deg;
  }
  return out;
}

}  // namespace sf::gsa
