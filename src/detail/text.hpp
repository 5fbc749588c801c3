#pragma once
// Small text helpers for error messages: numbers printed short and exact enough
// to act on.

#include <cstdio>
#include <string>

#include "interpatch/error.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::detail {

inline std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

inline std::string num(const Vec3& v) { return "(" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ")"; }

template <class... A>
std::string cat(const A&... a) {
  std::string s;
  auto add = [&s](const auto& x) {
    using X = std::decay_t<decltype(x)>;
    if constexpr (std::is_same_v<X, double> || std::is_same_v<X, float>) s += num(x);
    else if constexpr (std::is_same_v<X, Vec3>) s += num(x);
    else if constexpr (std::is_integral_v<X>) s += std::to_string(x);
    else s += x;
  };
  (add(a), ...);
  return s;
}

/// Throws interpatch::error with a message made of the parts.
template <class... A>
[[noreturn]] void fail(errc code, const A&... parts) {
  throw error(code, cat(parts...));
}

/// Refuses a parameter outside [0, 1], the domain of every construction; 1e-12 of
/// slack absorbs rounding in the caller's parameter mapping. Batch evaluations
/// check before their parallel loops: an exception must not leave an OpenMP region.
template <class Range>
void check_unit_parameters(const Range& ts, const char* dir) {
  for (double t : ts)
    if (!(t >= -1e-12 && t <= 1 + 1e-12))
      fail(errc::out_of_domain, "parameter ", dir, " = ", t, " is outside the domain [0, 1]");
}

}  // namespace interpatch::detail

// Internal invariants: checked in debug builds, compiled out in release.
#ifdef NDEBUG
#define INTERPATCH_ASSERT(cond) ((void)0)
#else
#include <cassert>
#define INTERPATCH_ASSERT(cond) assert(cond)
#endif
