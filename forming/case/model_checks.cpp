#include "forming/case/model_checks.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>

namespace sf::forming {
namespace {

// Rows of the constraint matrix on the rigid motions (t, w) of a ply, u(p) = t + w x p:
// component c fixed at point p gives the row [e_c, p x e_c].
void fix(std::vector<Eigen::Matrix<double, 1, 6>>& rows, const Vec3& p, int c) {
  Vec3 e = Vec3::Zero();
  e[c] = 1.0;
  Eigen::Matrix<double, 1, 6> row;
  row.head<3>() = e.transpose();
  row.tail<3>() = p.cross(e).transpose();
  rows.push_back(row);
}

// Corners of a side face of ply `p` (relative to the ply's centre, so rotations are well
// scaled) and the side's normal axis.
std::vector<Vec3> side_corners(const CasePly& p, PlySide side, int& normal) {
  const double hx = 0.5 * p.length_x, hy = 0.5 * p.length_y, hz = 0.5 * p.thickness;
  std::vector<Vec3> c;
  switch (side) {
    case PlySide::kX0:
    case PlySide::kX1:
      normal = 0;
      for (double y : {-hy, hy})
        for (double z : {-hz, hz}) c.emplace_back(side == PlySide::kX0 ? -hx : hx, y, z);
      break;
    case PlySide::kY0:
    case PlySide::kY1:
      normal = 1;
      for (double x : {-hx, hx})
        for (double z : {-hz, hz}) c.emplace_back(x, side == PlySide::kY0 ? -hy : hy, z);
      break;
    case PlySide::kBottom:
      normal = 2;
      for (double x : {-hx, hx})
        for (double y : {-hy, hy}) c.emplace_back(x, y, -hz);
      break;
  }
  return c;
}

// The rigid motions of ply `k` its conditions leave free ("translation along z, rotation
// about x"), or "" when none is.
std::string free_motions(const FormingCase& spec, int k) {
  const CasePly& p = spec.plies[static_cast<std::size_t>(k)];
  std::vector<Eigen::Matrix<double, 1, 6>> rows;
  for (const CaseBoundary& bc : spec.boundaries) {
    if (bc.ply_index != k) continue;
    int normal = 0;
    for (const Vec3& x : side_corners(p, bc.side, normal)) {
      for (int c = 0; c < 3; ++c) {
        const bool fixed = bc.kind == CaseBoundary::Kind::kClamp ||
                           (bc.kind == CaseBoundary::Kind::kDisplacement && bc.value[static_cast<std::size_t>(c)]) ||
                           (bc.kind == CaseBoundary::Kind::kSymmetry && c == normal);
        if (fixed) fix(rows, x, c);
      }
    }
  }
  // Scale the rotations by the ply's size so the rank test is unit-free.
  const double scale = std::max({p.length_x, p.length_y, p.thickness});
  Eigen::MatrixXd A(static_cast<Eigen::Index>(rows.size()), 6);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    A.row(static_cast<Eigen::Index>(i)) = rows[i];
    A.row(static_cast<Eigen::Index>(i)).tail<3>() /= scale;
  }
  const char* names[6] = {"translation along x", "translation along y", "translation along z",
                          "rotation about x",    "rotation about y",    "rotation about z"};
  if (rows.empty()) return "all six rigid-body motions (no boundary condition on it)";
  Eigen::FullPivLU<Eigen::MatrixXd> lu(A);
  lu.setThreshold(1e-9);
  const int n_free = 6 - static_cast<int>(lu.rank());
  if (n_free <= 0) return "";
  std::string list;
  for (int m = 0; m < 6; ++m)
    if (A.col(m).norm() < 1e-12) list += (list.empty() ? "" : ", ") + std::string(names[m]);
  if (list.empty()) list = std::to_string(n_free) + (n_free == 1 ? " combined motion" : " combined motions");
  return list;
}

bool in_contact(const FormingCase& spec, int k) {
  for (const CaseContact& c : spec.contacts)
    if (c.ply == k || c.with == k) return true;
  return false;
}

std::string bytes_text(double b) {
  if (b >= 1e9) return fmt::format("{:.1f} GB", b / 1e9);
  return fmt::format("{:.0f} MB", b / 1e6);
}

}  // namespace

double ModelEstimate::total_bytes() const { return 1.2 * (matrix_bytes + factor_bytes) + 8.0 * 40.0 * unknowns; }

ModelEstimate estimate_model(const FormingCase& spec) {
  ModelEstimate e;
  for (const CasePly& p : spec.plies) {
    // Two layers of surface nodes, 4 parameters (value, two derivatives, cross) x 3 coordinates.
    const double nodes = (static_cast<double>(p.n1) + 1.0) * (static_cast<double>(p.n2) + 1.0);
    const double dofs = 24.0 * nodes;
    e.unknowns += static_cast<std::int64_t>(dofs);
    // Each dof couples with the 3x3 surface nodes around it on both layers: 216 entries a
    // row; the lower triangle holds half, 12 bytes each (value and row index).
    e.matrix_bytes += dofs * 108.0 * 12.0;
    // Nested dissection on an n x n grid of 24-dof blocks: about 4 N log2 N blocks in L.
    e.factor_bytes += 24.0 * 24.0 * 4.0 * nodes * std::max(1.0, std::log2(nodes)) * 8.0;
  }
  return e;
}

double machine_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : 0.0;
}

void check_model(const FormingCase& spec, std::vector<CaseProblem>& problems, double memory_bytes) {
  const auto add = [&](ProblemKind kind, SourcePlace at, const std::string& message) {
    problems.push_back({kind, at, message, {}});
  };
  for (std::size_t k = 0; k < spec.plies.size(); ++k) {
    const CasePly& p = spec.plies[k];
    const std::string what = "ply '" + p.name + "'";
    bool geometry_ok = true;
    for (int c = 0; c < 3; ++c)
      if (!(std::abs(p.origin[c]) <= 1e6)) {
        add(ProblemKind::kOutOfRange, p.place,
            what + ": origin " + fmt::format("{:g}", p.origin[c]) +
                " mm lies beyond +-1e6 mm (1 km); the coordinates would lose their precision");
        geometry_ok = false;
      }
    for (const auto& [name, v] :
         {std::pair<const char*, double>{"size x", p.length_x}, {"size y", p.length_y}, {"thickness", p.thickness}})
      if (!(v >= 1e-4 && v <= 1e5)) {
        add(ProblemKind::kOutOfRange, p.place,
            what + ": " + name + " " + fmt::format("{:g}", v) + " mm is outside [1e-4, 1e5] mm");
        geometry_ok = false;
      }
    if (geometry_ok && p.thickness > std::min(p.length_x, p.length_y))
      add(ProblemKind::kOutOfRange, p.place,
          what + ": thickness " + fmt::format("{:g}", p.thickness) + " mm exceeds its width " +
              fmt::format("{:g}", std::min(p.length_x, p.length_y)) +
              " mm; a ply is a sheet (check size and thickness, in mm)");
    if (geometry_ok && (p.length_x / p.n1 < 1e-4 || p.length_y / p.n2 < 1e-4))
      add(ProblemKind::kOutOfRange, p.place, what + ": elements smaller than 1e-4 mm; give fewer elements");
  }
  if (!spec.solver.dynamic) {
    for (std::size_t k = 0; k < spec.plies.size(); ++k) {
      if (in_contact(spec, static_cast<int>(k))) continue;
      const std::string free = free_motions(spec, static_cast<int>(k));
      if (free.empty()) continue;
      const CasePly& p = spec.plies[k];
      add(ProblemKind::kNothingHeld, p.place,
          "ply '" + p.name + "' is not held: its boundary conditions leave " + free +
              " free, so a static solve has no unique answer (a singular stiffness); hold it with clamp, "
              "displacement or symmetry conditions, put it in contact, or use analysis: dynamic");
    }
  }
  if (memory_bytes > 0.0) {
    const ModelEstimate e = estimate_model(spec);
    if (e.total_bytes() > memory_bytes)
      add(ProblemKind::kOutOfRange, spec.plies.empty() ? SourcePlace{1, 1} : spec.plies.front().place,
          fmt::format("the model is too large for this machine: {} unknowns need about {} to solve, the machine has "
                      "{}; use fewer elements or plies",
                      e.unknowns, bytes_text(e.total_bytes()), bytes_text(memory_bytes)));
  }
}

}  // namespace sf::forming
