#pragma once
// Backtracking line search shared by the static and dynamic Newton solvers.
#include <limits>
#include <optional>

namespace sf::forming::detail {

// Armijo-type sufficient decrease of |r| in the line search.
inline constexpr double kSufficientDecrease = 1e-4;

struct LineSearch {
  double step = -1.0;    // step to take along the Newton correction; < 0: no trial could be evaluated
  bool stopped = false;  // norm_at asked to stop (a failure the caller reports)
};

// Trials at steps 1, 1/2, 1/4, ... (max_halvings + 1 of them). norm_at(step, stop)
// returns the free residual norm there, or std::nullopt when that state cannot be
// evaluated (an inverted element); setting `stop` ends the search at once. The first
// step with |r| <= (1 - 1e-4 step) rnorm is taken; failing that, the trial with the
// smallest |r|.
template <class NormAt>
LineSearch backtrack(double rnorm, int max_halvings, NormAt&& norm_at) {
  LineSearch out;
  double best_norm = std::numeric_limits<double>::infinity();
  double step = 1.0;
  for (int ls = 0; ls <= max_halvings; ++ls, step *= 0.5) {
    bool stop = false;
    const std::optional<double> norm = norm_at(step, stop);
    if (stop) {
      out.stopped = true;
      return out;
    }
    if (!norm) continue;
    if (*norm <= (1.0 - kSufficientDecrease * step) * rnorm) {
      out.step = step;
      return out;
    }
    if (*norm < best_norm) {
      best_norm = *norm;
      out.step = step;
    }
  }
  return out;
}

}  // namespace sf::forming::detail
