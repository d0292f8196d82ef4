// Throughput and accuracy of nearest-point projection (common/mesh/projection.hpp).
//
//   projection_bench
//
// A gently curved 200 x 200 mm sheet, z = 6 sin(pi x/200) sin(pi y/200) mm, is meshed
// with 20 x 20 and 60 x 60 bicubic Hermite elements. Random points are placed at a
// random (element, xi) and moved up to +-0.5 mm along the surface normal, so the
// exact distance is the offset; they are projected in one batch. The table gives the
// projector set-up time (element data + kd-tree), the projection time, points per
// second, and the mean/max |distance - |offset||. Fixed seed.

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <random>
#include <thread>
#include <vector>

#include "common/fe/surface_field.hpp"
#include "common/mesh/projection.hpp"
#include "common/mesh/surface_mesh.hpp"

namespace {

using sf::Index;
using sf::Vec2;
using sf::Vec3;
using Clock = std::chrono::steady_clock;

constexpr double kPi = 3.14159265358979323846;
constexpr double kSize = 200.0;     // mm
constexpr double kBump = 6.0;       // mm
constexpr double kMaxOffset = 0.5;  // mm

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

sf::mesh::SurfaceMesh sheet(int n) {
  using sf::mesh::SurfaceMesh;
  SurfaceMesh mesh = sf::mesh::make_rectangle_mesh(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), kSize, kSize, n, n);
  const double k = kPi / kSize;
  for (Index node = 0; node < mesh.n_nodes(); ++node) {
    const Vec3 q = mesh.node_position(node);
    const double x = q.x(), y = q.y();
    const double z = kBump * std::sin(k * x) * std::sin(k * y);
    const double zx = kBump * k * std::cos(k * x) * std::sin(k * y);
    const double zy = kBump * k * std::sin(k * x) * std::cos(k * y);
    mesh.geometry().row(SurfaceMesh::dof(node, sf::mesh::kValue)) = Vec3(x, y, z).transpose();
    mesh.geometry().row(SurfaceMesh::dof(node, sf::mesh::kD1)) = Vec3(1, 0, zx).normalized().transpose();
    mesh.geometry().row(SurfaceMesh::dof(node, sf::mesh::kD2)) = Vec3(0, 1, zy).normalized().transpose();
    mesh.geometry().row(SurfaceMesh::dof(node, sf::mesh::kD12)).setZero();
  }
  mesh.compute_arc_length_scale_factors();
  return mesh;
}

struct Cloud {
  sf::Points3 points;
  std::vector<double> distance;  // exact: |offset|
};

Cloud make_cloud(const sf::mesh::SurfaceMesh& mesh, Index n, unsigned seed) {
  const sf::fe::SurfaceField field(mesh, mesh.geometry());
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<Index> uel(0, mesh.n_elements() - 1);
  std::uniform_real_distribution<double> uxi(0.0, 1.0), uoff(-kMaxOffset, kMaxOffset);
  Cloud c;
  c.points.resize(n, 3);
  c.distance.resize(static_cast<std::size_t>(n));
  for (Index i = 0; i < n; ++i) {
    const Index e = uel(rng);
    const Vec2 xi(uxi(rng), uxi(rng));
    const auto s = field.evaluate3(e, xi, sf::basis::kValues | sf::basis::kFirst);
    const Vec3 normal = s.dx.col(0).cross(s.dx.col(1)).normalized();
    const double offset = uoff(rng);
    c.points.row(i) = (s.x + offset * normal).transpose();
    c.distance[static_cast<std::size_t>(i)] = std::abs(offset);
  }
  return c;
}

void run(int n_elements_per_side, const std::vector<Index>& sizes, int threads) {
  const auto mesh = sheet(n_elements_per_side);
  sf::mesh::ProjectionOptions options;
  options.threads = threads;
  const auto t_build = Clock::now();
  const sf::mesh::SurfaceProjector projector(mesh, mesh.geometry(), options);
  const double build = seconds_since(t_build);
  const int used_threads = threads > 0 ? threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  for (Index n : sizes) {
    const Cloud cloud = make_cloud(mesh, n, 20240611u + static_cast<unsigned>(n));
    const auto t0 = Clock::now();
    const std::clock_t c0 = std::clock();
    const auto result = projector.project_all(cloud.points);
    const double time = seconds_since(t0);
    const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    double sum = 0.0, worst = 0.0, iterations = 0.0;
    Index counts[4] = {0, 0, 0, 0};
    for (std::size_t i = 0; i < result.size(); ++i) {
      const double err = std::abs(result[i].distance - cloud.distance[i]);
      sum += err;
      worst = std::max(worst, err);
      iterations += result[i].iterations;
      ++counts[static_cast<int>(result[i].status)];
    }
    std::printf(
        "%2dx%-2d %8lld %7lld %3d %7.3f %8.3f %8.3f %10.0f %10.2e %10.2e %6.2f "
        "%lld/%lld/%lld/%lld\n",
        n_elements_per_side, n_elements_per_side, static_cast<long long>(n),
        static_cast<long long>(projector.n_samples()), used_threads, build, time, cpu, static_cast<double>(n) / time,
        sum / static_cast<double>(n), worst, iterations / static_cast<double>(n), static_cast<long long>(counts[0]),
        static_cast<long long>(counts[1]), static_cast<long long>(counts[2]), static_cast<long long>(counts[3]));
    std::fflush(stdout);
  }
}

}  // namespace

int main() {
  try {
    const auto t0 = Clock::now();
    std::printf("nearest-point projection: %g x %g mm sheet, bump %g mm, offsets within +-%g mm\n", kSize, kSize, kBump,
                kMaxOffset);
    std::printf("hardware threads: %u; options: candidates 8, samples 6x6 per element\n",
                std::thread::hardware_concurrency());
    std::printf(
        "build = element data + kd-tree (s); project = batch projection, wall clock (s);\n"
        "cpu = process CPU time of the projection, all threads (s);\n"
        "points/s = points / project;\n"
        "err = |distance - |offset|| (mm); iters = mean Newton iterations\n");
    std::printf("status = converged/on_free_edge/not_converged/failed\n\n");
    std::printf("%-5s %8s %7s %3s %7s %8s %8s %10s %10s %10s %6s %s\n", "mesh", "points", "samples", "thr", "build",
                "project", "cpu", "points/s", "mean err", "max err", "iters", "status");
    const std::vector<Index> sizes = {10000, 100000, 1000000};
    run(20, sizes, 0);
    run(60, sizes, 0);
    run(60, {1000000}, 1);  // scaling
    std::printf("\ntotal %.1f s\n", seconds_since(t0));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "projection_bench: %s\n", e.what());
    return 1;
  }
}
