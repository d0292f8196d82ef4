#include "forming/output/grid_out.hpp"

#include <algorithm>
#include <ostream>

#include "common/io/atomic_file.hpp"
#include "common/io/grid_file.hpp"
#include "forming/output/sampling.hpp"

namespace sf::forming {

void write_grid(const std::string& path, const FormingCase& spec, const Model& model, int b, const VecX& x, int n) {
  const CasePly& p = spec.plies[static_cast<std::size_t>(b)];
  const PlyMesh& ply = model.ply(b);
  const MatX xb = PlyMesh::unflatten(x.segment(model.offset(b), ply.n_dofs()));
  io::write_file_atomic(path, [&](std::ostream& out) {
    io::GridWriteOptions options;
    options.comments = {"simform --grid-out: " + std::to_string(n) + " x " + std::to_string(n) +
                        " marks on the top face of ply '" + p.name + "' (case " + spec.file + ")"};
    options.units = "mm";
    options.with_ij = true;
    io::GridFileWriter w(out, options);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double u = double(i) / (n - 1) * p.n1, v = double(j) / (n - 1) * p.n2;
        const int ie = std::min(static_cast<int>(u), p.n1 - 1), je = std::min(static_cast<int>(v), p.n2 - 1);
        const Index e = static_cast<Index>(je) * p.n1 + ie;
        const BrickPoint s = sample_brick(ply.element_parameters(e, ply.reference()), ply.element_parameters(e, xb),
                                          Vec3(u - ie, v - je, 1.0));
        w.add("m" + std::to_string(i) + "_" + std::to_string(j), s.X, s.x, i, j);
      }
  });
}

}  // namespace sf::forming
