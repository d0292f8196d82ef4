#include "forming/solve/step_history.hpp"

#include <sstream>
#include <utility>

namespace sf::forming {

std::string to_string(SolveStatus status) {
  switch (status) {
    case SolveStatus::kConverged:
      return "converged";
    case SolveStatus::kStepFailed:
      return "step-failed";
    case SolveStatus::kInvalidStart:
      return "invalid-start";
  }
  return "unknown";
}

void StepHistory::add(StepRecord step, bool keep) {
  total_iterations += step.iterations;
  if (step.converged) {
    ++n_converged_steps;
    if (!step.residual_norms.empty()) last_residual_ = step.residual_norms.back();
  } else {
    ++n_cutbacks;
  }
  if (keep) steps.push_back(std::move(step));
}

std::string StepHistory::counts() const {
  std::ostringstream os;
  os << "in " << n_converged_steps << " steps (" << n_cutbacks << " cut-backs), " << total_iterations
     << " Newton iterations";
  return os.str();
}

}  // namespace sf::forming
