// Registration accuracy and run time of `gsa compare` (gsa/compare.hpp) on a realistic size:
// two analyses of n x n marks (default 100 x 100 = 10,000), one of them misplaced by a known
// rigid motion, with and without digitisation noise; by shared ids and by surface (ICP).
//
//   build/bin/gsa_compare_bench [n] [noise_mm]
//
// Prints, per run: the rotation error (deg) and translation error (mm) of the recovered
// motion, the registration RMS distance (mm), the RMS of the major strain difference, and
// the seconds (wall clock and CPU of all threads) of the analyses (not part of compare) and of
// compare itself (registration, mapping of the marks and of the tessellated surface).

#include <Eigen/Geometry>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "gsa/analysis.hpp"
#include "gsa/compare.hpp"
#include "gsa/synthetic.hpp"

using namespace sf;
using namespace sf::gsa;

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

fe::RigidTransform misplacement() {
  fe::RigidTransform t;
  t.rotation = Eigen::AngleAxisd(0.07, Vec3(0.3, -0.4, 0.87).normalized()).toRotationMatrix();
  t.translation = Vec3(7.5, -4.0, 2.5);
  return t;
}

void run(const std::string& shape, int n, double noise, bool shared_ids) {
  SyntheticGridOptions go;
  go.n = n;
  go.spacing = 100.0 / (n - 1);  // a 100 x 100 mm blank
  const GridData sim = make_synthetic_grid(synthetic_case(shape), go);
  GridData meas = sim;
  const fe::RigidTransform t = misplacement();
  std::mt19937 rng(20240611u);
  std::normal_distribution<double> e(0.0, noise > 0 ? noise : 1.0);
  for (Index p = 0; p < meas.n_points(); ++p) {
    Vec3 x = t.apply(Vec3(meas.deformed.row(p).transpose()));
    if (noise > 0) x += Vec3(e(rng), e(rng), e(rng));
    meas.deformed.row(p) = x.transpose();
    if (!shared_ids) meas.ids[static_cast<std::size_t>(p)] = "m" + meas.ids[static_cast<std::size_t>(p)];
  }
  const auto t0 = Clock::now();
  const std::clock_t c0 = std::clock();
  const AnalysisResult rs = analyse(sim, {});
  const AnalysisResult rm = analyse(meas, {});
  const double t_analyse = since(t0);
  const double cpu_analyse = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  const CompareSide ss = compare_side_from(sim, rs, "simulated"), sm = compare_side_from(meas, rm, "measured");
  const auto t1 = Clock::now();
  const std::clock_t c1 = std::clock();
  const CompareResult r = compare(sm, ss, {});
  const double t_compare = since(t1);
  const double cpu_compare = static_cast<double>(std::clock() - c1) / CLOCKS_PER_SEC;
  const fe::RigidTransform expect = t.inverse();
  const double rot_err =
      Eigen::AngleAxisd(r.registration.transform.rotation * expect.rotation.transpose()).angle() * 180.0 / kPi;
  const double trans_err = (r.registration.transform.translation - expect.translation).norm();
  std::vector<double> major;
  Index matched = 0;
  for (const auto& c : r.marks) {
    major.push_back(c.difference[0]);
    matched += c.matched ? 1 : 0;
  }
  const Statistics st = statistics_of(major);
  std::printf(
      "%-5s %6d marks noise %.3f mm  %-19s rotation error %.2e deg  translation error %.2e mm  RMS %.2e mm  "
      "matched %lld  major diff RMS %.2e  analyses %.2f s (CPU %.2f s)  compare %.2f s (CPU %.2f s; registration %.3f, "
      "mapping %.3f)  iterations %d\n",
      shape.c_str(), n * n, noise, r.registration.method.c_str(), rot_err, trans_err, r.registration.rms,
      static_cast<long long>(matched), st.rms, t_analyse, cpu_analyse, t_compare, cpu_compare, r.seconds_registration,
      r.seconds_mapping, r.registration.iterations);
  std::fflush(stdout);
}
}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 100;
  const double noise = argc > 2 ? std::atof(argv[2]) : 0.02;
  if (n < 5) {
    std::fprintf(stderr, "usage: gsa_compare_bench [n >= 5] [noise_mm]\n");
    return 2;
  }
  run("dome", n, 0.0, true);
  run("dome", n, noise, true);
  run("wavy", n, 0.0, false);
  run("wavy", n, noise, false);
  return 0;
}
