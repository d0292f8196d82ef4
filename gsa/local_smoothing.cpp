#include "gsa/local_smoothing.hpp"

#include <algorithm>
#include <cmath>

#include "gsa/deformed_fit.hpp"

namespace sf::gsa {

namespace {

constexpr double kHeavyFactor = 100.0;  // the test fit's weight over the chosen one
constexpr double kMisfitSigmas = 4.0;   // mean residual over its noise standard deviation
constexpr double kRelaxed = 0.01;       // penalty multiplier of a relaxed element
constexpr int kMaxRounds = 3;

}  // namespace

Index LocalSmoothing::relaxed() const {
  return static_cast<Index>(std::count_if(multiplier.begin(), multiplier.end(), [](double v) { return v < 1.0; }));
}

LocalSmoothing relax_smoothing(DeformedProblem& problem, SmoothingChoice& choice, const NoiseEstimate& noise,
                               const FrameAndMesh& setup, const UndeformedFit& undeformed, const FitMarks& marks,
                               const std::function<SmoothingChoice()>& choose) {
  const mesh::SurfaceMesh& mesh = setup.mesh;
  const Index m = marks.size();
  LocalSmoothing out;
  out.multiplier.assign(static_cast<std::size_t>(mesh.n_elements()), 1.0);
  for (int round = 0; round < kMaxRounds; ++round) {
    const VecX& w = problem.weight();
    std::vector<std::vector<Index>> marks_of(static_cast<std::size_t>(mesh.n_elements()));
    for (Index k = 0; k < m; ++k)
      if (w[k] > 0)
        marks_of[static_cast<std::size_t>(undeformed.location[static_cast<std::size_t>(k)].element)].push_back(k);
    Penalty heavy = choice.penalty;
    heavy.delta *= kHeavyFactor;
    const FitResult fh = problem.fit(heavy, choice.passes);
    const MatX residual = MatX(problem.data()) - fh.fitted;
    std::vector<double> next = out.multiplier;
    int found = 0;
    for (Index e = 0; e < mesh.n_elements(); ++e) {
      if (out.multiplier[static_cast<std::size_t>(e)] < 1.0) continue;
      std::vector<Index> ks = marks_of[static_cast<std::size_t>(e)];
      for (int edge = 0; edge < 4; ++edge) {
        const Index nb = mesh.neighbour(e, edge).element;
        if (nb >= 0)
          ks.insert(ks.end(), marks_of[static_cast<std::size_t>(nb)].begin(),
                    marks_of[static_cast<std::size_t>(nb)].end());
      }
      if (ks.size() < 4) continue;
      Points3 at(static_cast<Index>(ks.size()), 3);
      Vec3 mean = Vec3::Zero();
      for (std::size_t i = 0; i < ks.size(); ++i) {
        at.row(static_cast<Index>(i)) = marks.undeformed.row(ks[i]);
        mean += residual.row(ks[i]).transpose();
      }
      mean /= static_cast<double>(ks.size());
      // |mean|^2 over three components against 3 var: a chi-square(3)/3 under noise alone.
      const double var = noise.mean_variance(at);
      if (var > 0 && mean.norm() > kMisfitSigmas * std::sqrt(3.0 * var)) {
        next[static_cast<std::size_t>(e)] = kRelaxed;
        ++found;
      }
    }
    if (found == 0) break;
    out.multiplier = next;
    ++out.rounds;
    problem.set_element_multipliers(out.multiplier);
    choice = choose();
  }
  // Every element relaxed alike is one lighter weight everywhere: folded into the
  // choice's weights (and the problem's multipliers back to 1), reported as such.
  if (out.relaxed() == mesh.n_elements() && !out.multiplier.empty()) {
    const auto [lo, hi] = std::minmax_element(out.multiplier.begin(), out.multiplier.end());
    if (*hi - *lo <= 1e-12 * *hi) {
      const double factor = *lo;
      for (double* w : {&choice.penalty.alpha, &choice.penalty.beta, &choice.penalty.gamma, &choice.penalty.delta,
                        &choice.penalty.boundary})
        *w *= factor;
      choice.log10_delta_optimum += std::log10(factor);
      out.multiplier.assign(out.multiplier.size(), 1.0);
      problem.set_element_multipliers(out.multiplier);
    }
  }
  return out;
}

}  // namespace sf::gsa
