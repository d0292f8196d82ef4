// Cost of contact per Newton iteration on laminates of flat plies: for n x n bricks per
// ply (n = 10, 20, 40) and 2 or 4 plies (100 x 100 mm, 0.5 mm each, stacked as
// separate bodies, every interface a BodyContact with 6 x 6 points per face, penalty
// plus viscous friction with quasi-static rates), prints one line per case:
//   points      contact points (slave Gauss points of every interface)
//   active      of them, those with a partner (a foot point on the master surface)
//   search_s    the search alone: recompute every master face's box, build the box tree
//               (forming/contact/box_tree.hpp) and query it at every contact point, s
//   us/point    search_s per contact point, microseconds
//   cand        candidate faces per contact point (boxes holding it within the reach)
//   force_s     one evaluation of every interface without tangent (search, projections,
//               laws, force), s
//   assembly_s  one evaluation with the consistent stiffness into the model's triplets
//               and their compression to a sparse matrix (what a Newton iteration pays
//               for contact), s
//   peak_MB     peak resident memory of the process so far (getrusage; a high-water mark)
// The state: every dof perturbed by up to 0.01 mm, each ply pressed 0.002 mm into the
// one below, each upper ply slid 0.01 mm in x over the step (dt = 0.1 s).
// Cost model: building the tree is O(F log F) for F master faces, a query O(log F + c)
// for c candidate faces; everything is linear in the number of contact points P up to
// the log factor (us/point stays flat as P grows 16 times).
// A program that prints figures, not a timed test.
//   build/bin/simform_contact_bench [max_elements_per_side=40]
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <vector>

#include "common/linalg/sparse.hpp"
#include "common/mesh/surface_mesh.hpp"
#include "forming/contact/body_contact.hpp"
#include "forming/contact/box_tree.hpp"
#include "forming/material/neo_hookean.hpp"
#include "forming/model/model.hpp"

using namespace sf;
using namespace sf::forming;

static double peak_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

template <class F>
static double seconds(F&& f, int repeat) {
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < repeat; ++i) f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / repeat;
}

int main(int argc, char** argv) {
  const int max_n = argc > 1 ? std::atoi(argv[1]) : 40;
  std::printf("%4s %6s %8s %8s %10s %9s %6s %10s %11s %8s\n", "n", "plies", "points", "active", "search_s", "us/point",
              "cand", "force_s", "assembly_s", "peak_MB");
  for (int n : {10, 20, 40}) {
    if (n > max_n) break;
    for (int plies : {2, 4}) {
      Model model;
      const auto law = std::make_shared<NeoHookean>(NeoHookeanParams{100.0, 100.0});
      for (int k = 0; k < plies; ++k)
        model.add_ply(
            PlyMesh(mesh::make_rectangle_mesh(Vec3(0, 0, 0.5 * k), Vec3::UnitX(), Vec3::UnitY(), 100.0, 100.0, n, n),
                    0.5, k % 2 ? 90.0 : 0.0),
            law);
      ContactOptions o;
      o.normal.stiffness = 100.0;
      o.friction.viscous = 0.02;
      std::vector<std::shared_ptr<BodyContact>> contacts;
      for (int k = 0; k + 1 < plies; ++k)
        contacts.push_back(std::make_shared<BodyContact>("i" + std::to_string(k), model,
                                                         ContactSurface::whole_face(model, k, true),
                                                         ContactSurface::whole_face(model, k + 1, false), o));
      VecX x = model.reference_positions();
      std::mt19937 rng(7);
      std::uniform_real_distribution<double> u(-1.0, 1.0);
      for (Index i = 0; i < x.size(); ++i) x(i) += 0.01 * u(rng);
      VecX previous = x;
      for (int k = 0; k < plies; ++k)
        for (Index node = 0; node < model.ply(k).n_nodes(); ++node) {
          x(model.dof(k, node, 0, 2)) -= 0.002 * k;
          previous(model.dof(k, node, 0, 0)) -= 0.01 * k;
        }
      const InteractionContext ctx{1.0, nullptr, &previous, 0.9};

      Index points = 0, active = 0;
      std::vector<std::vector<Vec3>> where(contacts.size());
      for (std::size_t i = 0; i < contacts.size(); ++i) {
        points += contacts[i]->n_points();
        for (const ContactPointRecord& r : contacts[i]->sample(x, ctx)) {
          active += r.partner;
          where[i].push_back(r.position);
        }
      }
      // The search alone, as BodyContact does it (reach: the two thicknesses).
      std::vector<Index> hits;
      Index candidates = 0;
      const double search_s = seconds(
          [&] {
            candidates = 0;
            for (std::size_t i = 0; i < contacts.size(); ++i) {
              const ContactSurface& m = contacts[i]->master();
              std::vector<Box> boxes;
              for (Index f = 0; f < m.n_faces(); ++f) boxes.push_back(face_box(m.basis(f), m.positions(f, x)));
              const BoxTree tree(std::move(boxes));
              for (const Vec3& p : where[i]) {
                tree.query(p, 1.0, hits);
                candidates += static_cast<Index>(hits.size());
              }
            }
          },
          n <= 20 ? 3 : 1);
      const Index n_dofs = model.n_dofs();
      const double force_s = seconds(
          [&] {
            InteractionSums sums;
            sums.force = VecX::Zero(n_dofs);
            for (const auto& c : contacts) c->add_to(x, ctx, sums);
          },
          n <= 20 ? 3 : 1);
      const double assembly_s = seconds(
          [&] {
            InteractionSums sums;
            sums.force = VecX::Zero(n_dofs);
            linalg::TripletAssembler k(n_dofs, n_dofs);
            sums.stiffness = &k;
            for (const auto& c : contacts) c->add_to(x, ctx, sums);
            const linalg::SparseMatrix K = k.compress();
            if (K.nonZeros() == 0) std::printf("(empty stiffness)\n");
          },
          n <= 20 ? 3 : 1);
      std::printf("%4d %6d %8ld %8ld %10.4f %9.3f %6.2f %10.4f %11.4f %8.1f\n", n, plies, static_cast<long>(points),
                  static_cast<long>(active), search_s, 1e6 * search_s / static_cast<double>(points),
                  static_cast<double>(candidates) / static_cast<double>(points), force_s, assembly_s, peak_mb());
      std::fflush(stdout);
    }
  }
  return 0;
}
