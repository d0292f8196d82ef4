// common/mesh/neighbours: the kd-tree searches against a brute-force search.
#include "common/mesh/neighbours.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace sf::mesh {
namespace {

// Scattered points on a curved sheet, the first 100 on a lattice (many equal distances),
// one row not finite.
Points3 sheet_points() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  Points3 p(400, 3);
  for (Index i = 0; i < p.rows(); ++i) {
    const double x = i < 100 ? static_cast<double>(i % 10) : u(rng), y = i < 100 ? static_cast<double>(i / 10) : u(rng);
    p.row(i) << x, y, 0.05 * x * x - 0.03 * x * y;
  }
  p.row(17).setConstant(std::numeric_limits<double>::quiet_NaN());
  return p;
}

std::vector<Index> brute_within(const Points3& p, Index i, double radius) {
  std::vector<Index> out;
  if (!p.row(i).allFinite()) return out;
  for (Index j = 0; j < p.rows(); ++j)
    if (j != i && p.row(j).allFinite() && (p.row(j) - p.row(i)).norm() <= radius) out.push_back(j);
  return out;
}

std::vector<Index> sorted(std::vector<Index> v) {
  std::sort(v.begin(), v.end());
  return v;
}

TEST(Neighbours, WithinRadiusFindsWhatBruteForceFindsAndNotItself) {
  const Points3 p = sheet_points();
  // Radii off the lattice's distances (1, 1.41, 2, 2.24, 2.83, 3 in the plane).
  for (const double radius : {0.7, 1.5, 2.9}) {
    const auto nb = neighbours_within(p, radius);
    ASSERT_EQ(nb.size(), static_cast<std::size_t>(p.rows()));
    for (Index i = 0; i < p.rows(); ++i) {
      const std::vector<Index> got = sorted(nb[static_cast<std::size_t>(i)]);
      EXPECT_EQ(got, brute_within(p, i, radius)) << "point " << i << ", radius " << radius;
      EXPECT_TRUE(std::find(got.begin(), got.end(), i) == got.end());
    }
    EXPECT_TRUE(nb[17].empty());  // the non-finite row has none ...
    for (const auto& list : nb)   // ... and is nobody's
      EXPECT_TRUE(std::find(list.begin(), list.end(), Index{17}) == list.end());
  }
}

TEST(Neighbours, WithinRadiusForQueriedRowsIsTheSameAsForAll) {
  const Points3 p = sheet_points();
  const auto all = neighbours_within(p, 1.5);
  const std::vector<Index> query = {3, 17, 250, 3, 399};
  const auto some = neighbours_within(p, 1.5, query);
  ASSERT_EQ(some.size(), query.size());
  for (std::size_t k = 0; k < query.size(); ++k)
    EXPECT_EQ(sorted(some[k]), sorted(all[static_cast<std::size_t>(query[k])])) << "query " << k;
  EXPECT_TRUE(some[1].empty());
}

TEST(Neighbours, NearestAreNearestFirstAndMatchBruteForce) {
  const Points3 p = sheet_points();
  const auto nb = nearest_neighbours(p, 6);
  for (Index i = 0; i < p.rows(); ++i) {
    const auto& got = nb[static_cast<std::size_t>(i)];
    if (i == 17) {
      EXPECT_TRUE(got.empty());
      continue;
    }
    ASSERT_EQ(got.size(), 6u);
    std::vector<double> d;
    for (Index j : got) d.push_back((p.row(j) - p.row(i)).norm());
    EXPECT_TRUE(std::is_sorted(d.begin(), d.end())) << "point " << i;
    // No other finite point is nearer than the sixth.
    for (Index j = 0; j < p.rows(); ++j) {
      if (j == i || j == 17 || std::find(got.begin(), got.end(), j) != got.end()) continue;
      EXPECT_GE((p.row(j) - p.row(i)).norm(), d.back() - 1e-12) << "point " << i << " misses " << j;
    }
  }
}

// The same lists, in the same order (ties on the lattice included), for queried rows as
// for all: gsa's strain test searches the marks it judges only.
TEST(Neighbours, NearestForQueriedRowsAreTheSameListsAsForAll) {
  const Points3 p = sheet_points();
  const auto all = nearest_neighbours(p, 8);
  std::vector<Index> query;
  for (Index i = 0; i < p.rows(); i += 3) query.push_back(i);
  query.push_back(17);
  query.push_back(44);
  const auto some = nearest_neighbours(p, 8, query);
  ASSERT_EQ(some.size(), query.size());
  for (std::size_t k = 0; k < query.size(); ++k)
    EXPECT_EQ(some[k], all[static_cast<std::size_t>(query[k])]) << "query " << k;
  EXPECT_TRUE(some[query.size() - 2].empty());
  EXPECT_EQ(some.back().size(), 8u);
}

}  // namespace
}  // namespace sf::mesh
