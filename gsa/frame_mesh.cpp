#include "gsa/frame_mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "common/core/error.hpp"
#include "common/fe/surface_field.hpp"
#include "common/mesh/projection.hpp"
#include "common/quadrature/gauss.hpp"
#include "gsa/mesh_file.hpp"

namespace sf::gsa {

namespace {

// Marks per element: ~9 for a few hundred marks, growing slowly up to 1e4 marks
// (22 x 22 elements on a square part); beyond that the element count stays. The
// fit-feasibility study found 6-9 elements a side best for 21 x 21 marks and 20-50
// for 1e5 marks; on a dense grid more elements only add unknowns (the
// factorisation's cost) while the part's shape, not the mark spacing, sets the
// resolution it needs. Measured on the 100 mm dome with 1e5 marks
// (gsa_stages_bench 1e5 N): 16, 20, 22, 24, 28 and 34 elements a side gave RMS
// strain errors 0.95, 1.16, 1.28, 1.42, 1.69 and 1.93e-4 and fit times 0.32,
// 0.45, 0.45, 0.61, 0.76 and 1.46 s. Parts with features smaller than an
// element (about a 22nd of the part) need --elements.
void choose_element_counts(Index n_marks, double len1, double len2, int& n1, int& n2) {
  constexpr double kDense = 1e4;
  const double n = std::clamp(static_cast<double>(n_marks), 1.0, kDense);
  const double total = std::max(1.0, n / (9.0 * std::pow(std::max(1.0, n / 441.0), 0.27)));
  n1 = std::max(1, static_cast<int>(std::lround(std::sqrt(total * len1 / len2))));
  n2 = std::max(1, static_cast<int>(std::lround(total / n1)));
  // A narrow strip gets at least three elements across (the minor strain varies across
  // a tensile specimen's width), as long as each keeps about four marks across.
  const double spacing = std::sqrt(len1 * len2 / n);
  for (auto [count, len] : {std::pair<int*, double>{&n1, len1}, std::pair<int*, double>{&n2, len2}}) {
    const int across = static_cast<int>(std::floor((len / spacing + 1.0) / 4.0));
    *count = std::max(*count, std::min(3, across));
  }
  n1 = std::min(n1, 300);
  n2 = std::min(n2, 300);
}

// Area of a mesh's surface (4 x 4 Gauss points per element).
double surface_area(const mesh::SurfaceMesh& mesh) {
  double area = 0.0;
  const auto rule = quadrature::gauss_2d(4, 4);
  const fe::SurfaceField geo(mesh, mesh.geometry());
  for (Index e = 0; e < mesh.n_elements(); ++e)
    for (int g = 0; g < rule.size(); ++g) {
      const Mat32 t = geo.evaluate3(e, rule.points[g], basis::kFirst).dx;
      area += rule.weights[g] * t.col(0).cross(t.col(1)).norm();
    }
  return area;
}

// An automatic mesh with the marks' starting locations on it.
struct AutoMesh {
  mesh::SurfaceMesh mesh;
  std::vector<MeshLocation> loc;
  int n1 = 0, n2 = 0;
  std::string layout;
  std::vector<double> breaks1, breaks2;
  Eigen::Vector2d low = Eigen::Vector2d::Zero(), length = Eigen::Vector2d::Zero();
};

// The cell of fraction f among ascending breaks 0 = b_0 < ... < b_n = 1.
int cell_of(const std::vector<double>& b, double f) {
  const int n = static_cast<int>(b.size()) - 1;
  const int i = static_cast<int>(std::upper_bound(b.begin(), b.end(), f) - b.begin()) - 1;
  return std::clamp(i, 0, n - 1);
}

// Keeps the elements of `full` that hold a mark, renumbering the locations.
AutoMesh drop_empty_elements(const mesh::SurfaceMesh& full, std::vector<MeshLocation> loc) {
  std::vector<bool> keep(static_cast<std::size_t>(full.n_elements()), false);
  for (const MeshLocation& l : loc) keep[static_cast<std::size_t>(l.element)] = true;
  std::vector<Index> emap;
  AutoMesh out;
  out.mesh = mesh::extract_elements(full, keep, &emap);
  for (MeshLocation& l : loc) l.element = emap[l.element];
  out.loc = std::move(loc);
  return out;
}

// Structured rectangle over the marks' bounding box in the plane (st: in-plane
// coordinates of the marks), n1 x n2 elements (0: from the number of marks).
AutoMesh rectangle_layout(const Eigen::MatrixX2d& st, const PlaneFrame& frame, const MeshOptions& options) {
  int n1 = options.elements1, n2 = options.elements2;
  const Eigen::Vector2d lo = st.colwise().minCoeff(), hi = st.colwise().maxCoeff();
  const double margin = 1e-6 * (hi - lo).maxCoeff();
  const Eigen::Vector2d lo_m = lo.array() - margin, len = (hi - lo).array() + 2 * margin;
  const bool graded = !options.breaks1.empty() && !options.breaks2.empty();
  if (graded) {
    n1 = static_cast<int>(options.breaks1.size()) - 1;
    n2 = static_cast<int>(options.breaks2.size()) - 1;
  } else if (n1 == 0 || n2 == 0) {
    choose_element_counts(st.rows(), len[0], len[1], n1, n2);
  }
  std::vector<double> b1(static_cast<std::size_t>(n1) + 1), b2(static_cast<std::size_t>(n2) + 1);
  for (int i = 0; i <= n1; ++i) b1[static_cast<std::size_t>(i)] = graded ? options.breaks1[i] : double(i) / n1;
  for (int j = 0; j <= n2; ++j) b2[static_cast<std::size_t>(j)] = graded ? options.breaks2[j] : double(j) / n2;
  const Vec3 origin = frame.centroid + lo_m[0] * frame.a1 + lo_m[1] * frame.a2;
  std::vector<double> s1, s2;  // the breaks in length units, for a graded mesh
  if (graded) {
    for (double b : b1) s1.push_back(b * len[0]);
    for (double b : b2) s2.push_back(b * len[1]);
  }
  const mesh::SurfaceMesh full = mesh::make_rectangle_mesh(origin, frame.a1, frame.a2, len[0], len[1], n1, n2, s1, s2);
  std::vector<MeshLocation> loc(static_cast<std::size_t>(st.rows()));
  for (Index k = 0; k < st.rows(); ++k) {
    const double f1 = (st(k, 0) - lo_m[0]) / len[0], f2 = (st(k, 1) - lo_m[1]) / len[1];
    if (!graded) {  // as before: the same floating-point steps on a uniform mesh
      const double u = f1 * n1, v = f2 * n2;
      const int i = std::clamp(static_cast<int>(std::floor(u)), 0, n1 - 1);
      const int j = std::clamp(static_cast<int>(std::floor(v)), 0, n2 - 1);
      loc[k] = {static_cast<Index>(j) * n1 + i, Vec2(std::clamp(u - i, 0.0, 1.0), std::clamp(v - j, 0.0, 1.0))};
      continue;
    }
    const int i = cell_of(b1, f1), j = cell_of(b2, f2);
    const double u = (f1 - b1[i]) / (b1[i + 1] - b1[i]), v = (f2 - b2[j]) / (b2[j + 1] - b2[j]);
    loc[k] = {static_cast<Index>(j) * n1 + i, Vec2(std::clamp(u, 0.0, 1.0), std::clamp(v, 0.0, 1.0))};
  }
  AutoMesh out = drop_empty_elements(full, std::move(loc));
  out.n1 = n1;
  out.n2 = n2;
  out.layout = std::to_string(n1) + "x" + std::to_string(n2) + (graded ? " (refined at a localised feature)" : "");
  out.breaks1 = std::move(b1);
  out.breaks2 = std::move(b2);
  out.low = lo_m;
  out.length = len;
  return out;
}

// The user's mesh, with the marks located on it by projection.
void user_mesh(const GridData& grid, const FitMarks& marks, const std::string& file, FrameAndMesh& out) {
  out.mesh = read_mesh_file(file);
  out.layout = "from " + file;
  const mesh::SurfaceProjector projector(out.mesh, out.mesh.geometry());
  const std::vector<mesh::Projection> proj = projector.project_all(marks.undeformed);
  out.start.resize(static_cast<std::size_t>(marks.size()));
  for (Index k = 0; k < marks.size(); ++k) {
    const Index p = marks.point[static_cast<std::size_t>(k)];
    if (!proj[k].ok())
      throw InputError(grid.where[p] + ": mark '" + grid.ids[p] + "' could not be located on the mesh " + file);
    out.start[k] = {proj[k].element, proj[k].xi};
  }
}

}  // namespace

FitMarks fit_marks(const GridData& grid) {
  FitMarks marks;
  marks.source = grid.sources.empty() ? std::string("grid") : grid.sources.front();
  for (Index p = 0; p < grid.n_points(); ++p)
    if (grid.has_undeformed(p)) marks.point.push_back(p);
  if (marks.point.size() < 6)
    throw InputError(marks.source + ": only " + std::to_string(marks.point.size()) +
                     " points have an undeformed position; at least 6 are needed for a surface fit");
  marks.undeformed.resize(marks.size(), 3);
  for (Index k = 0; k < marks.size(); ++k) marks.undeformed.row(k) = grid.undeformed.row(marks.point[k]);
  return marks;
}

FrameAndMesh build_frame_and_mesh(const GridData& grid, const FitMarks& marks, const MeshOptions& options) {
  FrameAndMesh out;
  const Index m = marks.size();
  out.frame = best_fit_plane(marks.undeformed);
  const PlaneFrame& frame = out.frame;
  if (!(frame.spread2 > 1e-6 * frame.spread1))
    throw InputError(marks.source + ": the undeformed points lie on a line (or coincide); a surface cannot be fitted");
  if (!options.file.empty()) {
    user_mesh(grid, marks, options.file, out);
  } else {
    Eigen::MatrixX2d st(m, 2);
    for (Index k = 0; k < m; ++k) {
      const Vec3 d = marks.undeformed.row(k).transpose() - frame.centroid;
      st(k, 0) = d.dot(frame.a1);
      st(k, 1) = d.dot(frame.a2);
    }
    AutoMesh am = rectangle_layout(st, frame, options);
    out.breaks1 = std::move(am.breaks1);
    out.breaks2 = std::move(am.breaks2);
    out.plane = std::move(st);
    out.plane_low = am.low;
    out.plane_length = am.length;
    out.mesh = std::move(am.mesh);
    out.start = std::move(am.loc);
    out.elements1 = am.n1;
    out.elements2 = am.n2;
    out.layout = am.layout;
  }
  out.mark_spacing = std::sqrt(surface_area(out.mesh) / static_cast<double>(m));
  out.penalties = assemble_penalties(out.mesh);
  return out;
}

}  // namespace sf::gsa
