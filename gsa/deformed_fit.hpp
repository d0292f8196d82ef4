#pragma once
// Stage 3 of `gsa analyse`: the deformed surface x(xi) on the same mesh and the same
// material coordinates as an undeformed fit (docs/theory/strain.md, "Deformed fit").
//
//   DeformedMarks data = deformed_marks(grid, marks, undeformed);
//   DeformedProblem problem(setup, marks, undeformed, data);
//   DeformedFit fit = fit_deformed(problem, penalty, flags);  // first fit, flagged marks left out
//   SmoothingChoice c = choose_smoothing_gcv(problem, smoothing, d);  // optional (gsa/smoothing.hpp)
//   refit_deformed(problem, fit, c);
//   readmit_deformed(problem, fit);
//   DeformedResiduals r = deformed_residuals(problem, fit);
//
// The smoothing acts on the deviation of x from the undeformed surface moved by the
// best-fit rigid motion of the marks, so a rigid motion of the deformed scan moves the
// fitted surface with it. Each mark's undeformed residual r = X - X(xi) travels with the
// mark: the fitted data are x - Q r, Q the rotation of the local deformation at the mark
// (the rigid rotation before there is a deformed surface).
//
// One undeformed fit serves any number of deformed states of the same marks: give each
// its own DeformedMarks and DeformedProblem.

#include <array>
#include <memory>
#include <vector>

#include "common/core/types.hpp"
#include "gsa/fit.hpp"
#include "gsa/frame_mesh.hpp"
#include "gsa/grid.hpp"
#include "gsa/outliers.hpp"
#include "gsa/plane.hpp"
#include "gsa/smoothing.hpp"
#include "gsa/undeformed_fit.hpp"

namespace sf::gsa {

// The deformed positions of the fit's marks.
struct DeformedMarks {
  Points3 position;  // m x 3 (NaN where not digitised)
  VecX weight;       // m: its base weight (1, or from its sigma) where the mark has a deformed position and
                     // took part in the undeformed fit; else 0
};
// `weight`: m base weights of the deformed positions (gsa/weights.hpp); empty: all 1.
// Throws sf::InputError naming the file when fewer than 6 marks have both positions.
DeformedMarks deformed_marks(const GridData& grid, const FitMarks& marks, const UndeformedFit& undeformed,
                             const VecX& weight = VecX());

// The deformed fit's data, reference and least-squares system for the current weights.
// Holds references to its arguments: they must outlive it.
class DeformedProblem {
 public:
  DeformedProblem(const FrameAndMesh& setup, const FitMarks& marks, const UndeformedFit& undeformed,
                  const DeformedMarks& deformed);
  ~DeformedProblem();
  DeformedProblem(const DeformedProblem&) = delete;
  DeformedProblem& operator=(const DeformedProblem&) = delete;

  // Sets the fitted data to x - Q r: Q the rigid rotation where `deformed` is null or a
  // mark is left out, else the polar rotation of the deformation of `deformed`
  // (n_dofs x 3) at the mark.
  void carry_residuals(const MatX* deformed);
  // Leaves mark k out (weight 0) or takes it in (its base weight, DeformedMarks::weight);
  // the next fit rebuilds the system.
  void set_weight(Index k, double weight);
  double base_weight(Index k) const { return deformed_.weight[k]; }
  // Fits the current data; throws sf::InputError naming the file when the system is singular.
  // `slot`: the system's workspace (FitSystem::solve); fits in different slots may run at
  // once on two threads once the system is built (weighted_values() builds it).
  FitResult fit(const Penalty& penalty, int passes, int slot = 0);
  // Two penalties at once (on two threads), with trace_probes Hutchinson probes for the
  // degrees of freedom; failures are reported in the results, not thrown.
  std::array<FitResult, 2> fit_pair(const std::array<Penalty, 2>& penalties, int trace_probes, int passes);

  // The smoother H of `penalty` applied to `values` (m x k, other data at the same marks
  // with the same weights, e.g. noise probes): their fit with a zero reference, at the
  // marks. The problem's own data stay as they are.
  MatX smooth(const MatX& values, const Penalty& penalty, int passes);
  // values - smooth(values, penalty, passes), without the copies (FitSystem::smoothing_residual).
  MatX smoothing_residual(const MatX& values, const Penalty& penalty, int passes);
  // Phi^T W values for the current weights (FitSystem::weighted_values), and the same
  // residuals from it in workspace `slot`: data smoothed with several penalties need it once.
  MatX weighted_values(const MatX& values);
  MatX smoothing_residual(const MatX& values, const MatX& weighted, const Penalty& penalty, int passes, int slot);
  // Probes for the trace estimates of later fit_pair() calls (FitSystem::set_probes),
  // kept when the system is rebuilt; their column count is the trace_probes to pass.
  void set_probes(MatX probes);
  // A penalty multiplier per element (locally relaxed smoothing); empty: 1 everywhere.
  void set_element_multipliers(std::vector<double> multipliers);
  const std::vector<double>& element_multipliers() const { return multipliers_; }

  const VecX& weight() const { return weight_; }
  const Points3& data() const { return data_; }                   // x - Q r, what is fitted
  const Points3& position() const { return deformed_.position; }  // the marks as digitised
  const RigidMotion& rigid() const { return rigid_; }
  const MatX& reference() const { return reference_; }  // U_ref: the undeformed surface moved rigidly

 private:
  FitSystem& system();

  const FrameAndMesh& setup_;
  const FitMarks& marks_;
  const UndeformedFit& undeformed_;
  const DeformedMarks& deformed_;
  VecX weight_;
  RigidMotion rigid_;
  MatX reference_;
  std::vector<Vec3> residual_u_;  // r = X - X(xi) per mark
  std::vector<Mat3> frame_u_;     // [X,1 X,2 N] per mark
  Points3 data_;                  // x - Q r
  std::unique_ptr<FitSystem> system_;
  bool rebuild_ = true;
  MatX probes_;
  std::vector<double> multipliers_;
  std::unique_ptr<PenaltyMatrices> relaxed_;  // penalties with the multipliers, when any differs from 1
};

struct DeformedFit {
  FitResult fit;    // the last solve (residuals of the carried data)
  Penalty penalty;  // its weights
  int passes = 1;
  std::vector<OutlierFlag> flags;  // marks left out, with reasons
};

// The first fit with `penalty` (residuals carried with the rigid rotation, then with the
// fitted one), the marks of `flags` (deformed outliers, gsa/outliers.hpp) left out.
DeformedFit fit_deformed(DeformedProblem& problem, const Penalty& penalty, std::vector<OutlierFlag> flags);
// Refits with a chosen smoothing, carrying the residuals once more with the new surface.
void refit_deformed(DeformedProblem& problem, DeformedFit& fit, const SmoothingChoice& choice);
// Takes flagged marks back that the final surface (fitted without them) passes within
// their threshold, and refits.
void readmit_deformed(DeformedProblem& problem, DeformedFit& fit);

struct DeformedResiduals {
  VecX residual;                // m: distance of each mark as digitised from x at its material point
  double rms = 0.0, max = 0.0;  // over the marks that took part
};
DeformedResiduals deformed_residuals(const DeformedProblem& problem, const DeformedFit& fit);

}  // namespace sf::gsa
