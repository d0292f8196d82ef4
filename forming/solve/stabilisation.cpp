#include "forming/solve/stabilisation.hpp"

#include <cmath>
#include <sstream>

#include "common/core/error.hpp"
#include "forming/solve/mass.hpp"

namespace sf::forming {

void StabiliseOptions::validate() const {
  auto bad = [](const char* field, const std::string& expected, double found) {
    std::ostringstream os;
    os << "solver stabilise " << field << ": expected " << expected << ", found " << found;
    throw InputError(os.str());
  };
  if (!(std::isfinite(fraction) && fraction >= 0.0 && fraction < 1.0))
    bad("fraction", "a fraction of the strain energy in [0, 1)", fraction);
  if (!(std::isfinite(damping) && damping >= 0.0)) bad("damping", "a finite value >= 0 (N s/mm^4)", damping);
  if (fraction > 0.0 && damping > 0.0)
    throw InputError("solver stabilise: give fraction or damping, not both");
  if (!(std::isfinite(warn_ratio) && warn_ratio > 0.0)) bad("warn_ratio", "a ratio > 0", warn_ratio);
}

ViscousStabilisation::ViscousStabilisation(const Model& model, double damping)
    : mass_(mass_matrix(model, std::vector<double>(static_cast<std::size_t>(model.n_bodies()), 1.0))) {
  set_damping(damping);
  rows_.reserve(static_cast<std::size_t>(mass_.nonZeros()));
  cols_.reserve(rows_.capacity());
  values_.reserve(rows_.capacity());
  for (int k = 0; k < mass_.outerSize(); ++k)
    for (linalg::SparseMatrix::InnerIterator it(mass_, k); it; ++it) {
      rows_.push_back(it.row());
      cols_.push_back(it.col());
      values_.push_back(it.value());
    }
}

void ViscousStabilisation::set_damping(double c) {
  if (!(std::isfinite(c) && c >= 0.0)) {
    std::ostringstream os;
    os << "stabilisation damping: expected a finite value >= 0 (N s/mm^4), found " << c;
    throw InputError(os.str());
  }
  c_ = c;
}

void ViscousStabilisation::add_to(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                                  InteractionSums& sums) const {
  if (!(c_ > 0.0) || context.previous == nullptr || !(context.time > context.previous_time)) return;
  const double k = c_ / (context.time - context.previous_time);  // N/mm per mm^3 of M*
  const VecX d = x - *context.previous;
  sums.force.noalias() += k * (mass_ * d);
  if (!sums.stiffness) return;
  for (std::size_t i = 0; i < values_.size(); ++i) sums.stiffness->add(rows_[i], cols_[i], k * values_[i]);
}

double ViscousStabilisation::mass_norm(const Eigen::Ref<const VecX>& d) const { return d.dot(mass_ * d); }

double ViscousStabilisation::dissipation(const Eigen::Ref<const VecX>& from, const Eigen::Ref<const VecX>& to,
                                         double dt) const {
  if (!(c_ > 0.0 && dt > 0.0)) return 0.0;
  return c_ * mass_norm(to - from) / dt;
}

double calibrated_damping(const ViscousStabilisation& s, double fraction, double strain_energy_increase,
                          const Eigen::Ref<const VecX>& dx, double dt) {
  const double m = s.mass_norm(dx);
  if (!(fraction > 0.0 && strain_energy_increase > 0.0 && m > 0.0 && dt > 0.0)) return 0.0;
  return fraction * strain_energy_increase * dt / m;
}

}  // namespace sf::forming
