#include "forming/contact/surface_contact.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <utility>

#include "common/core/error.hpp"

namespace sf::forming {
namespace {

// Rounding band of the normal law (contact_law.hpp): delta = this x thickness.
constexpr double kBand = 1e-3;
// Default engage gap of the viscous layer, relative to the slave ply's thickness.
constexpr double kEngage = 1e-2;

// The local block of one (slave face, master face) pair while a slave face is summed.
struct PairBlock {
  Index master_face = -1;
  const FaceDofs* master_dofs = nullptr;
  LocalContribution local;
};

void scatter(const FaceDofs& slave, const FaceDofs* master, int slave_size, const LocalContribution& c, bool half_pass,
             InteractionSums& sums) {
  std::vector<Index> dofs;
  std::vector<double> coefs;
  std::vector<int> local;
  const auto append = [&](const FaceDofs& d, int shift) {
    for (std::size_t j = 0; j < d.dofs.size(); ++j) {
      dofs.push_back(d.dofs[j]);
      coefs.push_back(d.coefs[j]);
      local.push_back(d.local[j] + shift);
    }
  };
  append(slave, 0);
  if (master) append(*master, slave_size);
  const int m = static_cast<int>(dofs.size());
  // Half pass: rows of the slave side only (its entries come first).
  const int rows = half_pass ? static_cast<int>(slave.dofs.size()) : m;
  for (int a = 0; a < rows; ++a) sums.force(dofs[a]) += coefs[a] * c.force(local[a]);
  const std::vector<Index> row_dofs(dofs.begin(), dofs.begin() + rows);
  const auto add = [&](const MatX& k, linalg::TripletAssembler* target, linalg::PatternAssembler* pattern) {
    if (!target || k.size() == 0) return;
    MatX block(rows, m);
    for (int cc = 0; cc < m; ++cc)
      for (int a = 0; a < rows; ++a) block(a, cc) = coefs[a] * coefs[cc] * k(local[a], local[cc]);
    if (pattern) {  // straight into the kept pattern (InteractionSums::pattern)
      pattern->add_block(row_dofs, dofs, block.data(), rows);
      sums.pattern_entries += static_cast<long>(rows) * m;
    } else {
      target->add_block(row_dofs, dofs, block);
    }
  };
  add(c.stiffness, sums.stiffness, sums.pattern);
  add(c.damping, sums.damping, nullptr);
}

}  // namespace

void ContactOptions::validate() const {
  normal.validate();
  friction.validate();
  if (points < 1 || points > 12)
    throw InputError("contact points: expected 1..12 points per face direction, found " + std::to_string(points));
  if (!(std::isfinite(band) && band >= 0.0)) {
    std::ostringstream os;
    os << "contact band: expected a length >= 0 (mm; 0 = default), found " << band;
    throw InputError(os.str());
  }
  if (!(std::isfinite(search_distance) && search_distance >= 0.0)) {
    std::ostringstream os;
    os << "contact search_distance: expected a length >= 0 (mm; 0 = default), found " << search_distance;
    throw InputError(os.str());
  }
}

SurfaceContact::SurfaceContact(std::string name, const Model& model, ContactSurface slave, ContactOptions options)
    : name_(std::move(name)), slave_(std::move(slave)), options_(options) {
  options_.validate();
  rule_ = quadrature::gauss_2d(options_.points, options_.points);
  const VecX X = model.reference_positions();
  for (Index f = 0; f < slave_.n_faces(); ++f) {
    const FaceBasis& fb = slave_.basis(f);
    const MatX pos = slave_.positions(f, X);
    std::vector<FaceBasisValues> values;
    for (int q = 0; q < rule_.size(); ++q) {
      const Vec2& st = rule_.points[static_cast<std::size_t>(q)];
      const FaceBasisValues v = fb.evaluate(st[0], st[1], false);
      Vec3 xs = Vec3::Zero(), xt = Vec3::Zero();
      for (int a = 0; a < v.n; ++a) {
        xs += v.ds[static_cast<std::size_t>(a)] * pos.row(a).transpose();
        xt += v.dt[static_cast<std::size_t>(a)] * pos.row(a).transpose();
      }
      weight_.push_back(rule_.weights[static_cast<std::size_t>(q)] * xs.cross(xt).norm());
      values.push_back(v);
    }
    point_basis_.push_back(std::move(values));
  }
  lambda_.assign(weight_.size(), 0.0);
  slip_.assign(weight_.size(), Vec3::Zero());
  elastic_.assign(weight_.size(), Vec3::Zero());
  elastic_before_ = elastic_;
}

NormalLaw SurfaceContact::normal_law() const {
  NormalLaw law = options_.normal;
  if (law.tail > 0.0 && law.tail_reach == 0.0 && law.tail_release == 0.0) law.tail_release = 0.9 * search_reach();
  return law;
}

double SurfaceContact::engage_gap() const {
  return options_.friction.engage_gap >= 0.0 ? options_.friction.engage_gap : kEngage * slave_.thickness();
}

namespace {
std::atomic<long> g_flips{0};
}  // namespace

long contact_state_flips() { return g_flips.load(std::memory_order_relaxed); }

void SurfaceContact::report_flips(std::vector<signed char>& status,
                                  const std::vector<Eigen::Matrix<double, 5, 1>>& where, bool tracing) const {
  // Status: -1 no partner; else normal (0 open, 1 band, 2 closed) + 4 x viscous (0 off,
  // 1 taper, 2 engaged). Kinds of change: 0 the search edge (a partner found or lost),
  // 1 the band's open end (bearing on or off: pressing against the tail's tie or nothing),
  // 2 the band's closed end, 3 across the whole band in one iteration, 4 the viscous layer.
  static const char* const kKind[] = {"search edge", "open end", "closed end", "across band", "viscous"};
  const bool known = flip_status_.size() == status.size();
  int count[4] = {0, 0, 0, 0}, kinds[5] = {0, 0, 0, 0, 0}, changed = 0;
  std::ostringstream os;
  os.precision(4);
  for (std::size_t i = 0; i < status.size(); ++i) {
    const int now = status[i];
    ++count[now < 0 ? 0 : (now % 4) + 1];
    if (!known || flip_status_[i] == now) continue;
    const int before = flip_status_[i];
    const int nb = before < 0 ? -1 : before % 4, nn = now < 0 ? -1 : now % 4;
    const int vb = before < 0 ? 0 : before / 4, vn = now < 0 ? 0 : now / 4;
    int kind = 4;
    if (nb != nn) {
      // Without a tail an open point carries nothing, whether it has a partner or not.
      if ((nb < 0 || nn < 0) && options_.normal.tail == 0.0 && std::max(before, now) == 0) continue;
      if (nb < 0 || nn < 0)
        kind = 0;
      else if (std::min(nb, nn) == 0 && std::max(nb, nn) == 1)
        kind = 1;
      else if (std::min(nb, nn) == 1)
        kind = 2;
      else
        kind = 3;
    } else if (vb == vn) {
      continue;
    }
    ++kinds[kind];
    ++changed;
    if (tracing && changed <= 8)
      os << " [" << kKind[kind] << " " << before << ">" << now << " x " << where[i][0] << " y " << where[i][1]
         << " z " << where[i][2] << " g " << where[i][3] << " p " << where[i][4] << "]";
  }
  g_flips.fetch_add(changed, std::memory_order_relaxed);
  if (tracing) {
    std::fprintf(stderr,
                 "contact %s: none %d open %d band %d closed %d; changed %d (search edge %d, open end %d, closed end %d, "
                 "across band %d, viscous %d)%s\n",
                 name_.c_str(), count[0], count[1], count[2], count[3], changed, kinds[0], kinds[1], kinds[2], kinds[3],
                 kinds[4], os.str().c_str());
  }
  flip_status_ = std::move(status);
}

void SurfaceContact::evaluate(const Eigen::Ref<const VecX>& x, const InteractionContext& context, InteractionSums* sums,
                              std::vector<ContactPointRecord>* records) const {
  const bool tangent = sums && sums->stiffness;
  const bool damping = sums && sums->damping && context.velocity;
  // Rates: velocities, or finite differences from the previous state.
  const VecX* rates = nullptr;
  VecX rate_storage;
  double inv_dt = 0.0;
  if (context.velocity) {
    rates = context.velocity;
  } else if (context.previous && context.time > context.previous_time) {
    inv_dt = 1.0 / (context.time - context.previous_time);
    rate_storage = (x - *context.previous) * inv_dt;
    rates = &rate_storage;
  }
  const bool friction = options_.friction.active() && rates;
  // Coulomb regularised by slip distance (contact_law.hpp): quasi-static rates only.
  const bool distance = options_.friction.coulomb > 0.0 && options_.friction.stick_slip > 0.0;
  if (distance && context.velocity)
    throw InputError("contact " + name_ +
                     ": stick_slip (Coulomb friction regularised by slip distance) needs a quasi-static run; give "
                     "stick_velocity (mm/s) for a dynamic one");
  // The elastic slip the evaluated step started from: a step already committed (its
  // outputs are sampled after the commit) started from the e before that commit.
  const std::vector<Vec3>& elastic = context.previous_time < committed_time_ ? elastic_before_ : elastic_;
  const std::unique_ptr<Prepared> prepared = prepare(x, context, rates, context.previous);
  const double band = options_.band > 0.0 ? options_.band : kBand * slave_.thickness();
  const double engage = engage_gap();
  const NormalLaw normal_law = this->normal_law();
  // Each point's state at this tangent assembly (once per Newton iteration), against the
  // last one: the points that changed are counted (contact_state_flips()) and, with
  // SF_NEWTON_TRACE=1 or SF_CONTACT_TRACE=1, listed on stderr with where they are.
  static const bool trace = std::getenv("SF_CONTACT_TRACE") != nullptr || std::getenv("SF_NEWTON_TRACE") != nullptr;
  const bool tracking = tangent;
  const bool tracing = trace && tangent;
  std::vector<signed char> status;
  std::vector<Eigen::Matrix<double, 5, 1>> where;  // x, y, z, gap, pressure of each point
  if (tracking) status.assign(static_cast<std::size_t>(n_points()), -1);
  if (tracing) where.assign(static_cast<std::size_t>(n_points()), Eigen::Matrix<double, 5, 1>::Zero());
  std::vector<PairBlock> blocks;
  for (Index f = 0; f < slave_.n_faces(); ++f) {
    const SurfaceFace& sf = slave_.face(f);
    const int ns = slave_.basis(f).n_active();
    const MatX pos = slave_.positions(f, x);
    MatX rate_pos, prev_pos;
    if (rates) rate_pos = slave_.positions(f, *rates);
    if (context.previous) prev_pos = slave_.positions(f, *context.previous);
    std::size_t n_blocks = 0;  // blocks in use; the rest keep their storage for the next faces
    for (int q = 0; q < points_per_face(); ++q) {
      const std::size_t id = static_cast<std::size_t>(f * points_per_face() + q);
      const FaceBasisValues& v = point_basis_[static_cast<std::size_t>(f)][static_cast<std::size_t>(q)];
      PointKinematics k;
      k.n = k.n_slave = ns;
      Vec3 xs = Vec3::Zero(), vs = Vec3::Zero(), dxs = Vec3::Zero();
      for (int a = 0; a < ns; ++a) {
        const double na = v.value[static_cast<std::size_t>(a)];
        k.phi[static_cast<std::size_t>(a)] = na;
        xs += na * pos.row(a).transpose();
        if (rates) vs += na * rate_pos.row(a).transpose();
        if (context.previous) dxs += na * (pos.row(a) - prev_pos.row(a)).transpose();
      }
      ContactPointRecord rec;
      rec.face = f;
      rec.st = rule_.points[static_cast<std::size_t>(q)];
      rec.position = xs;
      rec.slip = Vec3::Zero();  // the step's increment (below); sample() puts the accumulated slip
      rec.weight = weight_[id];
      Partner partner;
      if (!find_partner(*prepared, xs, k, partner)) {
        if (records) records->push_back(rec);
        continue;
      }
      PointLaw law;
      law.normal = normal_response(normal_law, k.gap, lambda_[id], band);
      // The viscous layer: engaged up to the engage gap g_v, tapering smoothly (C1) to
      // nothing over one band width beyond it, so a point whose gap crosses g_v does
      // not switch its friction on and off between Newton iterates (a jump in the
      // residual the tangent cannot see).
      if (options_.friction.viscous > 0.0) {
        const double s = (k.gap - engage) / band;
        if (s <= 0.0) {
          law.viscous = options_.friction.viscous;
        } else if (s < 1.0) {
          law.viscous = options_.friction.viscous * (1.0 - s * s * (3.0 - 2.0 * s));
          law.viscous_slope = -options_.friction.viscous * 6.0 * s * (1.0 - s) / band;
        }
      }
      law.coulomb = options_.friction.coulomb;
      law.stick_velocity = options_.friction.stick_velocity;
      PointRates pr;
      if (friction) {
        pr.have = true;
        pr.relative = vs - partner.velocity;
        pr.inv_dt = inv_dt;
        pr.master_d1 = partner.velocity_d1;
        pr.master_d2 = partner.velocity_d2;
        if (distance) {  // in rate terms: eps = d / dt, the elastic slip as a rate e / dt
          law.distance = true;
          law.stick_velocity = options_.friction.stick_slip * inv_dt;
          pr.coulomb_shift = elastic[id] * inv_dt;
        }
      }
      rec.partner = true;
      rec.gap = k.gap;
      rec.normal = k.normal;
      if (tracking) {
        const int normal =
            law.normal.bearing <= 0.0 ? 0 : law.normal.bearing_stiffness >= options_.normal.stiffness ? 2 : 1;
        const int viscous = law.viscous <= 0.0 ? 0 : law.viscous_slope != 0.0 ? 1 : 2;
        status[id] = static_cast<signed char>(normal + 4 * viscous);
        if (tracing) where[id] << xs.x(), xs.y(), xs.z(), k.gap, law.normal.pressure;
      }
      const bool contributes = law.normal.pressure != 0.0 || law.normal.stiffness > 0.0 ||
                               (pr.have && (law.viscous > 0.0 || (law.coulomb > 0.0 && law.normal.bearing > 0.0)));
      if (!contributes) {
        if (records) records->push_back(rec);
        continue;
      }
      PointState st;
      if (sums) {
        const auto end = blocks.begin() + static_cast<std::ptrdiff_t>(n_blocks);
        auto it = std::find_if(blocks.begin(), end,
                               [&](const PairBlock& b) { return b.master_face == partner.master_face; });
        if (it == end) {
          if (n_blocks == blocks.size()) blocks.emplace_back();
          PairBlock& b = blocks[n_blocks++];
          b.master_face = partner.master_face;
          b.master_dofs = partner.master_dofs;
          const int m = 3 * k.n;
          b.local.energy = 0.0;
          b.local.force.setZero(m);
          if (tangent) {
            b.local.stiffness.setZero(m, m);
            // The points' low-rank factors, multiplied out once per pair (contact_kernel.hpp).
            b.local.defer_stiffness(points_per_face());
          }
          if (damping) b.local.damping.setZero(m, m);
          it = blocks.begin() + static_cast<std::ptrdiff_t>(n_blocks - 1);
        }
        st = add_contact_point(k, law, pr, weight_[id], it->local);
      } else {
        LocalContribution scratch;
        scratch.force = VecX::Zero(3 * k.n);
        st = add_contact_point(k, law, pr, weight_[id], scratch);
      }
      if (records) {
        rec.pressure = st.pressure;
        rec.slip_rate = st.slip_rate;
        rec.shear = st.shear;
        // The elastic slip this state would commit: s d / max(|s|, d), s = v_T,c dt.
        if (law.distance && law.normal.bearing > 0.0) {
          const Vec3 sl = st.coulomb_slip_rate / inv_dt;
          const double d = options_.friction.stick_slip;
          rec.elastic_slip = sl * (d / std::max(sl.norm(), d));
        }
        // The tangential relative displacement since the previous state (commit).
        if (context.previous) {
          const Vec3 d = dxs - partner.displacement;
          rec.slip = d - k.normal * k.normal.dot(d);  // the increment; commit() adds it
        }
        records->push_back(rec);
      }
    }
    if (sums)
      for (std::size_t i = 0; i < n_blocks; ++i) {
        PairBlock& b = blocks[i];
        if (tangent) b.local.finish_stiffness();
        sums->energy += options_.half_pass ? 0.5 * b.local.energy : b.local.energy;
        scatter(sf.dofs, b.master_dofs, 3 * ns, b.local, options_.half_pass, *sums);
      }
  }
  if (tracking) report_flips(status, where, tracing);
}

void SurfaceContact::pattern_blocks(
    const Eigen::Ref<const VecX>& x, const InteractionContext& context,
    const std::function<void(const std::vector<Index>& rows, const std::vector<Index>& cols)>& block) const {
  const std::unique_ptr<Prepared> prepared = prepare(x, context, nullptr, nullptr);
  std::vector<Index> masters;
  std::vector<Index> rows, cols;
  for (Index f = 0; f < slave_.n_faces(); ++f) {
    const SurfaceFace& sf = slave_.face(f);
    const int ns = slave_.basis(f).n_active();
    const MatX pos = slave_.positions(f, x);
    masters.clear();
    for (int q = 0; q < points_per_face(); ++q) {
      const FaceBasisValues& v = point_basis_[static_cast<std::size_t>(f)][static_cast<std::size_t>(q)];
      PointKinematics k;
      k.n = k.n_slave = ns;
      Vec3 xs = Vec3::Zero();
      for (int a = 0; a < ns; ++a) {
        k.phi[static_cast<std::size_t>(a)] = v.value[static_cast<std::size_t>(a)];
        xs += v.value[static_cast<std::size_t>(a)] * pos.row(a).transpose();
      }
      Partner partner;
      if (!find_partner(*prepared, xs, k, partner)) continue;
      if (std::find(masters.begin(), masters.end(), partner.master_face) != masters.end()) continue;
      masters.push_back(partner.master_face);
      rows = sf.dofs.dofs;  // as scatter(): the slave's rows (a half pass: only those)
      cols = rows;
      if (partner.master_dofs)
        cols.insert(cols.end(), partner.master_dofs->dofs.begin(), partner.master_dofs->dofs.end());
      if (!options_.half_pass) rows = cols;
      block(rows, cols);
    }
  }
}

void SurfaceContact::add_to(const Eigen::Ref<const VecX>& x, const InteractionContext& context,
                            InteractionSums& sums) const {
  evaluate(x, context, &sums, nullptr);
}

std::vector<ContactPointRecord> SurfaceContact::sample(const Eigen::Ref<const VecX>& x,
                                                       const InteractionContext& context) const {
  std::vector<ContactPointRecord> out;
  out.reserve(static_cast<std::size_t>(n_points()));
  evaluate(x, context, nullptr, &out);
  // evaluate() leaves the step's slip increment in `slip` when a previous state is
  // given; the output wants the accumulated slip.
  for (std::size_t i = 0; i < out.size(); ++i) out[i].slip = slip_[i];
  return out;
}

void SurfaceContact::commit(const Eigen::Ref<const VecX>& x, const InteractionContext& context) {
  if (!context.previous) return;
  std::vector<ContactPointRecord> rec;
  rec.reserve(static_cast<std::size_t>(n_points()));
  evaluate(x, context, nullptr, &rec);
  const bool dynamic = context.velocity != nullptr;
  if (dynamic && !shear_known_) {
    // The traction at the interval's start: a run from rest at t = 0 has it with the
    // bodies at rest (tools may already move); otherwise (a restart) the end's is used.
    shear_.assign(rec.size(), Vec3::Zero());
    if (context.previous_time == 0.0) {
      const VecX rest = VecX::Zero(x.size());
      std::vector<ContactPointRecord> start;
      start.reserve(rec.size());
      evaluate(*context.previous, InteractionContext{0.0, &rest, nullptr, 0.0}, nullptr, &start);
      for (std::size_t i = 0; i < start.size(); ++i) shear_[i] = start[i].shear;
    } else {
      for (std::size_t i = 0; i < rec.size(); ++i) shear_[i] = rec[i].shear;
    }
  }
  // A step committed twice (its e already moved on) keeps the e it started from.
  if (!(context.previous_time < committed_time_)) elastic_before_ = elastic_;
  committed_time_ = context.time;
  for (std::size_t i = 0; i < rec.size(); ++i) {
    const Vec3 traction = dynamic ? Vec3(0.5 * (shear_[i] + rec[i].shear)) : rec[i].shear;
    if (dynamic) shear_[i] = rec[i].shear;
    elastic_[i] = rec[i].elastic_slip;
    if (!rec[i].partner) continue;
    slip_[i] += rec[i].slip;  // the increment over the step
    dissipated_ += (options_.half_pass ? 0.5 : 1.0) * rec[i].weight * (-traction).dot(rec[i].slip);
  }
  shear_known_ = dynamic;
}

MultiplierUpdate SurfaceContact::update_multipliers(const Eigen::Ref<const VecX>& x,
                                                    const InteractionContext& context) {
  MultiplierUpdate out;
  if (!options_.normal.augmented) return out;
  out.tolerance = options_.normal.tolerance;
  std::vector<ContactPointRecord> rec;
  rec.reserve(static_cast<std::size_t>(n_points()));
  evaluate(x, context, nullptr, &rec);
  for (const ContactPointRecord& r : rec)
    if (r.partner && r.pressure > 0.0) out.violation = std::max(out.violation, -r.gap);
  out.converged = out.violation <= out.tolerance;
  if (out.converged) return out;
  for (std::size_t i = 0; i < rec.size(); ++i) lambda_[i] = rec[i].partner ? rec[i].pressure : 0.0;
  ++updates_;
  return out;
}

}  // namespace sf::forming
