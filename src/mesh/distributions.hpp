#pragma once
// Distributions of nodes 0 = σ_0 < ... < σ_m = 1 over m cells, as a grading asks
// them: a geometric progression from one end, Vinokur's two-sided stretching, and
// the counts that fit within a largest growth.

#include <cstddef>
#include <span>
#include <vector>

#include "interpatch/grading.hpp"

namespace interpatch::mesh {

// The nodes of a distribution over m cells: a ratio, a first cell a, a last cell b,
// or both ends. Empty when none fits m cells.
std::vector<double> sigma_nodes(const Grading& g, double a, double b, std::size_t m);

// The largest ratio of neighbouring cells, either way.
double growth_of(std::span<const double> s);

// The largest count the search for one that fits tries: more nodes than any mesh
// needs along one direction.
inline constexpr std::size_t count_limit = 100'000;

// The count nearest `count` whose distribution fits within max_growth, or 0.
std::size_t count_that_fits(const Grading& g, double a, double b, std::size_t count);

}  // namespace interpatch::mesh
