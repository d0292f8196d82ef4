#include "forming/model/model.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <limits>
#include <sstream>
#include <utility>

#include "common/core/error.hpp"
#include "common/core/parallel.hpp"
#include "forming/model/solve_profile.hpp"

namespace sf::forming {
namespace {

// A number with 4 significant digits, for messages.
std::string short_number(double v) {
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
}

}  // namespace

Model::Model(ElementRule rule) : rule_(rule), brick_rule_(rule.brick()), kernel_(brick_rule_) {}

namespace {
std::atomic<bool> g_band_pattern{true};
}  // namespace

void Model::set_band_pattern(bool on) { g_band_pattern.store(on); }
bool Model::band_pattern() { return g_band_pattern.load(); }

int Model::threads() const { return threads_ > 0 ? threads_ : sf::default_threads(); }

int Model::add_ply(PlyMesh ply, std::shared_ptr<const Material> material, const ConstraintTerms& constraints) {
  if (!material) throw InputError("model: ply added without a material");
  constraints.validate();
  if (constraints.inextensible && material->fibre_direction().isZero(0.0))
    throw InputError("model: fibre inextensibility asked for a material without fibres (" + material->name() + ")");
  const Index n = ply.n_dofs();
  const Index ne = ply.n_elements();
  Body b{std::move(ply), std::move(material), n_dofs_, constraints, {}, {}};
  if (constraints.active()) {
    b.p.assign(static_cast<std::size_t>(ne), constraints.p);
    b.T.assign(static_cast<std::size_t>(ne), constraints.T);
  }
  bodies_.push_back(std::move(b));
  n_dofs_ += n;
  const int body = n_bodies() - 1;
  const Body& added = bodies_.back();
  for (Index e = 0; e < ne; ++e) {
    bricks_.emplace_back(body, e);
    const ElementDofs ed = element_dofs(body, e);
    entries_.push_back({ed.dofs, ed.coefs, ed.local});
    reference_params_.push_back(added.ply.element_parameters(e, added.ply.reference()));
  }
  colours_ = linalg::colour_elements(n_dofs_, entries_);
  return body;
}

int Model::add_interaction(std::shared_ptr<Interaction> interaction) {
  if (!interaction) throw InputError("model: interaction added as a null pointer");
  interactions_.push_back(std::move(interaction));
  return n_interactions() - 1;
}

bool Model::symmetric_tangent() const {
  for (const std::shared_ptr<Interaction>& i : interactions_)
    if (!i->symmetric()) return false;
  return true;
}

bool Model::any_constrained() const {
  for (const Body& b : bodies_)
    if (b.constraints.active()) return true;
  return false;
}

void Model::set_multipliers(int body, std::vector<double> p, std::vector<double> T) {
  Body& b = bodies_.at(static_cast<std::size_t>(body));
  SF_ASSERT(static_cast<Index>(p.size()) == b.ply.n_elements() && static_cast<Index>(T.size()) == b.ply.n_elements(),
            "one multiplier per element");
  b.p = std::move(p);
  b.T = std::move(T);
}

ConstraintTerms Model::element_constraints(const Body& b, Index e) const {
  ConstraintTerms c = b.constraints;
  if (c.active()) {
    c.p = b.p[static_cast<std::size_t>(e)];
    c.T = b.T[static_cast<std::size_t>(e)];
  }
  return c;
}

std::vector<Model::ConstraintState> Model::constraint_state(int body, const Eigen::Ref<const VecX>& x) const {
  const Body& b = bodies_.at(static_cast<std::size_t>(body));
  std::vector<ConstraintState> out;
  if (!b.constraints.active()) return out;
  const MatX xb = PlyMesh::unflatten(x.segment(b.offset, b.ply.n_dofs()));
  for (Index e = 0; e < b.ply.n_elements(); ++e) {
    const ElementResult r =
        brick_element(b.ply.element_parameters(e, b.ply.reference()), b.ply.element_parameters(e, xb), *b.material,
                      brick_rule_, false, element_constraints(b, e));
    out.push_back({r.g_J, r.g_T, r.p_eff, r.T_eff, r.volume});
  }
  return out;
}

VecX Model::reference_positions() const {
  VecX x(n_dofs_);
  for (const Body& b : bodies_) x.segment(b.offset, b.ply.n_dofs()) = b.ply.reference_dofs();
  return x;
}

std::vector<bool> Model::used_dofs() const {
  std::vector<bool> used(n_dofs_, false);
  for (const Body& b : bodies_)
    for (Index e = 0; e < b.ply.n_elements(); ++e) {
      const BrickMap map = b.ply.element_map(e);
      for (int k = 0; k < kBrickFunctions; ++k)
        for (int t = 0; t < map.n_terms[k]; ++t)
          if (map.terms[k][t].coef != 0.0)
            for (int i = 0; i < 3; ++i) used[b.offset + 3 * map.terms[k][t].dof + i] = true;
    }
  return used;
}

Model::ElementDofs Model::element_dofs(int body, Index e) const {
  const Body& b = bodies_[body];
  const BrickMap map = b.ply.element_map(e);
  ElementDofs out;
  for (int k = 0; k < kBrickFunctions; ++k)
    for (int t = 0; t < map.n_terms[k]; ++t)
      for (int i = 0; i < 3; ++i) {
        out.dofs.push_back(b.offset + 3 * map.terms[k][t].dof + i);
        out.coefs.push_back(map.terms[k][t].coef);
        out.local.push_back(3 * k + i);
      }
  return out;
}

Assembly Model::assemble(const Eigen::Ref<const VecX>& x, bool want_tangent) const {
  return assemble(x, InteractionContext{}, want_tangent);
}

Assembly Model::assemble(const Eigen::Ref<const VecX>& x, const InteractionContext& context, bool want_tangent) const {
  if (!want_tangent) return assemble_into(x, context, nullptr);
  // The full tangent over every dof, through a pattern built for this call.
  linalg::PatternAssembler full = make_pattern(std::vector<bool>(static_cast<std::size_t>(n_dofs_), true), false);
  Assembly out = assemble_into(x, context, &full);
  if (out.ok) out.tangent = std::move(full.matrix());
  return out;
}

linalg::PatternAssembler Model::make_pattern(const std::vector<bool>& active, bool symmetric) const {
  SF_ASSERT(static_cast<Index>(active.size()) == n_dofs_, "one flag per dof");
  return linalg::PatternAssembler(n_dofs_, active, entries_,
                                  symmetric ? linalg::Storage::kLower : linalg::Storage::kFull);
}

namespace {

// Per-thread buffers of the element loop (kept between assemblies: OpenMP's threads persist).
struct ThreadWork {
  BrickScratch scratch;
  ElementResult result;
  BrickParams x_e;
  Eigen::Matrix<double, kBrickDofs, 1> v_e, y_e;
};

}  // namespace

Assembly Model::assemble_into(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                              linalg::PatternAssembler* tangent, const VecX* direction) const {
  SF_ASSERT(x.size() == n_dofs_, "positions must have n_dofs entries");
  SF_ASSERT(!direction || direction->size() == n_dofs_, "direction must have n_dofs entries");
  SF_ASSERT(!tangent || (tangent->n_dofs() == n_dofs_ && tangent->n_elements() == static_cast<Index>(bricks_.size())),
            "pattern made for another model");
  const auto t_start = std::chrono::steady_clock::now();
  Assembly out;
  out.force = VecX::Zero(n_dofs_);
  if (direction) out.tangent_times = VecX::Zero(n_dofs_);
  if (tangent) tangent->set_zero();
  const bool need_k = tangent != nullptr || direction != nullptr;
  const std::vector<std::vector<Index>>& colours = tangent ? tangent->colours() : colours_;
  const Index n_el = static_cast<Index>(bricks_.size());
  std::vector<double> energies(static_cast<std::size_t>(n_el), 0.0);
  std::atomic<Index> first_failed{n_el};
  std::vector<ElementResult::Status> status(static_cast<std::size_t>(n_el), ElementResult::Status::kOk);
  std::vector<double> min_det(static_cast<std::size_t>(n_el), 0.0);
  const double* xp = x.data();
  double* force = out.force.data();
  double* ktimes = direction ? out.tangent_times.data() : nullptr;
  // At least kMinElementsPerThread bricks (~5 ms of kernels) per thread: below that the
  // barriers between colours cost more than they save, badly so on a loaded machine
  // where a waiting thread spins while the other is descheduled.
  constexpr Index kMinElementsPerThread = 48;
  const int n_threads = std::max(1, std::min(threads(), static_cast<int>(n_el / kMinElementsPerThread)));
  std::atomic<bool> input_error{false};
  std::string input_message;
#pragma omp parallel num_threads(n_threads)
  {
    thread_local ThreadWork w;
    for (const std::vector<Index>& colour : colours) {
      const Index n_c = static_cast<Index>(colour.size());
#pragma omp for schedule(dynamic, 4)
      for (Index i = 0; i < n_c; ++i) {
        const Index g = colour[static_cast<std::size_t>(i)];
        if (first_failed.load(std::memory_order_relaxed) < n_el || input_error.load(std::memory_order_relaxed))
          continue;
        const auto [body, e] = bricks_[static_cast<std::size_t>(g)];
        const Body& b = bodies_[static_cast<std::size_t>(body)];
        const linalg::ElementEntries& en = entries_[static_cast<std::size_t>(g)];
        const int m = static_cast<int>(en.dofs.size());
        w.x_e.setZero();
        double* xe = w.x_e.data();  // column-major 32 x 3: entry 3 k + i at k + 32 i
        for (int a = 0; a < m; ++a) {
          const int l = en.local[static_cast<std::size_t>(a)];
          xe[l / 3 + kBrickFunctions * (l % 3)] +=
              en.coefs[static_cast<std::size_t>(a)] * xp[en.dofs[static_cast<std::size_t>(a)]];
        }
        try {
          kernel_.evaluate(reference_params_[static_cast<std::size_t>(g)], w.x_e, *b.material, need_k,
                           element_constraints(b, e), w.scratch, w.result);
        } catch (const std::exception& ex) {  // bad constraint input: rethrown after the loop
#pragma omp critical(sf_model_input_error)
          {
            if (!input_error.load()) input_message = ex.what();
            input_error.store(true);
          }
          continue;
        }
        const ElementResult& r = w.result;
        status[static_cast<std::size_t>(g)] = r.status;
        min_det[static_cast<std::size_t>(g)] = r.min_det_f;
        if (!r.ok()) {
          Index seen = first_failed.load();
          while (g < seen && !first_failed.compare_exchange_weak(seen, g)) {
          }
          continue;
        }
        energies[static_cast<std::size_t>(g)] = r.energy;
        for (int a = 0; a < m; ++a)
          force[en.dofs[static_cast<std::size_t>(a)]] +=
              en.coefs[static_cast<std::size_t>(a)] * r.force(en.local[static_cast<std::size_t>(a)]);
        if (tangent) tangent->add_element(g, r.tangent.data(), kBrickDofs);
        if (direction) {
          w.v_e.setZero();
          bool any = false;
          for (int a = 0; a < m; ++a) {
            const double v = (*direction)(en.dofs[static_cast<std::size_t>(a)]);
            if (v != 0.0) {
              w.v_e(en.local[static_cast<std::size_t>(a)]) += en.coefs[static_cast<std::size_t>(a)] * v;
              any = true;
            }
          }
          if (any) {
            w.y_e.noalias() = r.tangent * w.v_e;
            for (int a = 0; a < m; ++a)
              ktimes[en.dofs[static_cast<std::size_t>(a)]] +=
                  en.coefs[static_cast<std::size_t>(a)] * w.y_e(en.local[static_cast<std::size_t>(a)]);
          }
        }
      }
    }
  }
  if (input_error.load()) throw InputError(input_message);
  // The element that failed first in element order among those evaluated: with
  // failures, the loop skips elements, so which one is named may depend on the timing;
  // that the state is inadmissible does not.
  if (first_failed.load() < n_el) {
    const Index g = first_failed.load();
    const auto [body, e] = bricks_[static_cast<std::size_t>(g)];
    out.ok = false;
    out.message = "body " + std::to_string(body) + " element " + std::to_string(e) + ": " +
                  to_string(status[static_cast<std::size_t>(g)]) + " (min det F " +
                  short_number(min_det[static_cast<std::size_t>(g)]) + ")";
    out.energy = std::numeric_limits<double>::infinity();
    return out;
  }
  for (double en : energies) out.energy += en;
  out.strain_energy = out.energy;
  out.element_force_norm = out.force.norm();
  SolveProfile& profile = solve_profile();
  const auto t_elements = std::chrono::steady_clock::now();
  profile.elements_s += std::chrono::duration<double>(t_elements - t_start).count();
  ++profile.assemblies;
  if (interactions_.empty()) return out;
  // Room for as many contact triplets as the last assembly on this thread had (plus a
  // margin): millions of them at the full dome, whose repeated doubling and copying
  // showed as a third of the contact bench's time (bench/simform_contact_bench.cpp).
  thread_local Index triplet_hint = 0;
  linalg::TripletAssembler stiffness(n_dofs_, n_dofs_);
  if (need_k && triplet_hint > 0) stiffness.reserve(triplet_hint + triplet_hint / 8);
  // Contact pairs' stiffness goes straight into the kept pattern, unless K d is wanted
  // too (the predictor's direction: then through the triplets).
  const bool added = add_interactions(x, context, need_k, stiffness, out, direction ? nullptr : tangent);
  if (need_k) triplet_hint = stiffness.n_triplets();
  const auto t_merge = std::chrono::steady_clock::now();
  profile.contact_eval_s += std::chrono::duration<double>(t_merge - t_elements).count();
  if (added && need_k) merge_interactions(x, context, stiffness, tangent, direction, out);
  const auto t_end = std::chrono::steady_clock::now();
  profile.contact_merge_s += std::chrono::duration<double>(t_end - t_merge).count();
  profile.contact_s += std::chrono::duration<double>(t_end - t_elements).count();
  return out;
}

void Model::merge_interactions(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                               const linalg::TripletAssembler& stiffness, linalg::PatternAssembler* tangent,
                               const VecX* direction, Assembly& out) const {
  for (const Eigen::Triplet<double, int>& t : stiffness.triplets()) {
    if (tangent) tangent->add(t.row(), t.col(), t.value());
    if (direction) out.tangent_times(t.row()) += t.value() * (*direction)(t.col());
  }
  SolveProfile& profile = solve_profile();
  if (tangent && tangent->has_pending() && band_pattern()) {
    // The pattern grows (a new symbolic analysis follows): lay it out for every pair
    // within the interactions' bands at once, adding explicit zeros.
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& interaction : interactions_)
      interaction->pattern_blocks(x, context,
                                  [tangent](const std::vector<Index>& rows, const std::vector<Index>& cols) {
                                    for (Index c : cols)
                                      for (Index r : rows) tangent->add(r, c, 0.0);
                                  });
    profile.band_layout_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  profile.contact_entries += static_cast<long>(stiffness.triplets().size());
  if (tangent && tangent->flush()) ++profile.pattern_growths;
}

Assembly Model::assemble_reference(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                                   bool want_tangent) const {
  SF_ASSERT(x.size() == n_dofs_, "positions must have n_dofs entries");
  Assembly out;
  out.force = VecX::Zero(n_dofs_);
  linalg::TripletAssembler triplets(n_dofs_, n_dofs_);
  if (want_tangent) {
    Index n_el = 0;
    for (const Body& b : bodies_) n_el += b.ply.n_elements();
    triplets.reserve(n_el * kBrickDofs * kBrickDofs);
  }
  MatX block;
  for (int body = 0; body < n_bodies(); ++body) {
    const Body& b = bodies_[body];
    const MatX xb = PlyMesh::unflatten(x.segment(b.offset, b.ply.n_dofs()));
    for (Index e = 0; e < b.ply.n_elements(); ++e) {
      const BrickParams X_e = b.ply.element_parameters(e, b.ply.reference());
      const BrickParams x_e = b.ply.element_parameters(e, xb);
      const ElementResult r =
          brick_element(X_e, x_e, *b.material, brick_rule_, want_tangent, element_constraints(b, e));
      if (!r.ok()) {
        out.ok = false;
        out.message = "body " + std::to_string(body) + " element " + std::to_string(e) + ": " + to_string(r.status) +
                      " (min det F " + short_number(r.min_det_f) + ")";
        out.energy = std::numeric_limits<double>::infinity();
        return out;
      }
      out.energy += r.energy;
      // Expanded local -> global list: one entry per (function, map term, coordinate);
      // duplicates (collapsed elements) are summed by the assembler.
      const ElementDofs ed = element_dofs(body, e);
      const std::vector<Index>& dofs = ed.dofs;
      const std::vector<double>& coefs = ed.coefs;
      const std::vector<int>& local = ed.local;
      const int m = static_cast<int>(dofs.size());
      for (int a = 0; a < m; ++a) out.force(dofs[a]) += coefs[a] * r.force(local[a]);
      if (!want_tangent) continue;
      block.resize(m, m);
      for (int c = 0; c < m; ++c)
        for (int a = 0; a < m; ++a) block(a, c) = coefs[a] * coefs[c] * r.tangent(local[a], local[c]);
      triplets.add_block(dofs, dofs, block);
    }
  }
  out.strain_energy = out.energy;
  out.element_force_norm = out.force.norm();
  if (!interactions_.empty() && !add_interactions(x, context, want_tangent, triplets, out)) return out;
  if (want_tangent) out.tangent = triplets.compress();
  return out;
}

bool Model::add_interactions(const Eigen::Ref<const VecX>& x, const InteractionContext& context, bool want_tangent,
                             linalg::TripletAssembler& stiffness, Assembly& out,
                             linalg::PatternAssembler* pattern) const {
  SF_ASSERT(!context.velocity || context.velocity->size() == n_dofs_, "velocities must have n_dofs entries");
  linalg::TripletAssembler damping(n_dofs_, n_dofs_);
  InteractionSums sums;
  sums.force = std::move(out.force);
  sums.stiffness = want_tangent ? &stiffness : nullptr;
  sums.damping = want_tangent && context.velocity ? &damping : nullptr;
  sums.pattern = want_tangent ? pattern : nullptr;
  bool velocity_dependent = false;
  for (const std::shared_ptr<Interaction>& interaction : interactions_) {
    interaction->add_to(x, context, sums);
    if (!sums.ok) {
      out.ok = false;
      out.message = interaction->name() + ": " + sums.message;
      out.energy = std::numeric_limits<double>::infinity();
      out.force = std::move(sums.force);
      return false;
    }
    velocity_dependent = velocity_dependent || interaction->needs_velocity();
  }
  solve_profile().contact_entries += sums.pattern_entries;
  out.energy += sums.energy;
  out.force = std::move(sums.force);
  if (sums.damping && velocity_dependent) out.damping = damping.compress();
  return true;
}

std::vector<Mat3> Model::deformation_gradients(int body, const Eigen::Ref<const VecX>& x) const {
  const Body& b = bodies_[body];
  const MatX xb = PlyMesh::unflatten(x.segment(b.offset, b.ply.n_dofs()));
  std::vector<Mat3> out;
  for (Index e = 0; e < b.ply.n_elements(); ++e) {
    const std::vector<Mat3> f = brick_deformation_gradients(b.ply.element_parameters(e, b.ply.reference()),
                                                            b.ply.element_parameters(e, xb), brick_rule_);
    out.insert(out.end(), f.begin(), f.end());
  }
  return out;
}

Vec3 largest_displacement(const Model& model, const Eigen::Ref<const VecX>& x, const Eigen::Ref<const VecX>& X) {
  Vec3 largest = Vec3::Zero();
  for (int b = 0; b < model.n_bodies(); ++b)
    for (Index nd = 0; nd < model.ply(b).n_nodes(); ++nd) {
      Vec3 u;
      for (int c = 0; c < 3; ++c) u[c] = x[model.dof(b, nd, 0, c)] - X[model.dof(b, nd, 0, c)];
      if (u.norm() > largest.norm()) largest = u;
    }
  return largest;
}

}  // namespace sf::forming
