#include "common/mesh/neighbours.hpp"

// CGAL stays in this translation unit (header-only, slow to compile, private link).
#include <CGAL/Fuzzy_sphere.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Search_traits_adapter.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/property_map.h>

#include <boost/iterator/function_output_iterator.hpp>

#include <iterator>
#include <numeric>
#include <utility>

#include "common/core/parallel.hpp"

namespace sf::mesh {

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Sample = std::pair<Point, Index>;
using SamplePointMap = CGAL::First_of_pair_property_map<Sample>;
using Traits = CGAL::Search_traits_adapter<Sample, SamplePointMap, CGAL::Search_traits_3<Kernel>>;
using Search = CGAL::Orthogonal_k_neighbor_search<Traits>;
using Tree = Search::Tree;
using Sphere = CGAL::Fuzzy_sphere<Traits>;

std::vector<Sample> finite_samples(const Points3& points) {
  std::vector<Sample> s;
  s.reserve(static_cast<std::size_t>(points.rows()));
  for (Index p = 0; p < points.rows(); ++p)
    if (points.row(p).allFinite()) s.emplace_back(Point(points(p, 0), points(p, 1), points(p, 2)), p);
  return s;
}

// The search's output: each point found other than `self` goes straight into `nb`, in the
// order found (no list of samples per query to copy from).
struct KeepOthers {  // assignable, as CGAL's search needs of its output iterator
  std::vector<Index>* nb;
  Index self;
  void operator()(const Sample& f) const {
    if (f.second != self) nb->push_back(f.second);
  }
};
auto keep_others(std::vector<Index>& nb, Index self) {
  return boost::make_function_output_iterator(KeepOthers{&nb, self});
}

// The k nearest points to `at` other than `self`, nearest first, into `nb`.
void nearest_others(const Tree& tree, const Point& at, Index self, int k, std::vector<Index>& nb) {
  // k + 1: the query point finds itself first.
  Search search(tree, at, static_cast<unsigned>(k) + 1);
  nb.reserve(static_cast<std::size_t>(k));
  for (auto it = search.begin(); it != search.end(); ++it)
    if (it->first.second != self && static_cast<int>(nb.size()) < k) nb.push_back(it->first.second);
}

}  // namespace

std::vector<std::vector<Index>> nearest_neighbours(const Points3& points, int k) {
  std::vector<Index> all(static_cast<std::size_t>(points.rows()));
  std::iota(all.begin(), all.end(), Index{0});
  return nearest_neighbours(points, k, all);
}

std::vector<std::vector<Index>> nearest_neighbours(const Points3& points, int k, const std::vector<Index>& query) {
  std::vector<std::vector<Index>> out(query.size());
  const std::vector<Sample> samples = finite_samples(points);
  if (samples.size() < 2 || k <= 0) return out;
  Tree tree(samples.begin(), samples.end());
  tree.build();  // before the queries: a built tree is searched from several threads
  parallel_for(static_cast<Index>(query.size()), [&](Index i) {
    const Index p = query[static_cast<std::size_t>(i)];
    if (points.row(p).allFinite())
      nearest_others(tree, Point(points(p, 0), points(p, 1), points(p, 2)), p, k, out[static_cast<std::size_t>(i)]);
  });
  return out;
}

std::vector<std::vector<Index>> neighbours_within(const Points3& points, double radius) {
  std::vector<std::vector<Index>> out(static_cast<std::size_t>(points.rows()));
  const std::vector<Sample> samples = finite_samples(points);
  if (samples.size() < 2 || !(radius > 0.0)) return out;
  Tree tree(samples.begin(), samples.end());
  tree.build();
  parallel_for(static_cast<Index>(samples.size()), [&](Index i) {
    const Sample& s = samples[static_cast<std::size_t>(i)];
    std::vector<Index>& nb = out[static_cast<std::size_t>(s.second)];
    tree.search(keep_others(nb, s.second), Sphere(s.first, radius, 0.0));
  });
  return out;
}

std::vector<std::vector<Index>> neighbours_within(const Points3& points, double radius,
                                                  const std::vector<Index>& query) {
  std::vector<std::vector<Index>> out(query.size());
  const std::vector<Sample> samples = finite_samples(points);
  if (samples.size() < 2 || !(radius > 0.0)) return out;
  Tree tree(samples.begin(), samples.end());
  tree.build();
  parallel_for(
      static_cast<Index>(query.size()),
      [&](Index i) {
        const Index p = query[static_cast<std::size_t>(i)];
        if (!points.row(p).allFinite()) return;
        tree.search(keep_others(out[static_cast<std::size_t>(i)], p),
                    Sphere(Point(points(p, 0), points(p, 1), points(p, 2)), radius, 0.0));
      },
      16);
  return out;
}

}  // namespace sf::mesh
