#pragma once
// Unit normals of many points at once, for meshes.

#include <cstddef>

#include "interpatch/vec3.hpp"

namespace interpatch::detail {

/// out[j] = unit_normal of the partials su[j], sv[j] (suv[j] at a pole) for j < n:
/// four points at a time where the partials are of ordinary size and not nearly
/// parallel (the plain formulas, which unit_normal's scaling then leaves unchanged
/// but for rounding), unit_normal itself at the others.
void unit_normals(const Vec3* su, const Vec3* sv, const Vec3* suv, std::size_t n, Vec3* out);

}  // namespace interpatch::detail
