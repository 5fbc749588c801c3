#pragma once
// Small text helpers for error messages: numbers printed short and exact enough
// to act on.

#include <cstdint>
#include <cstdio>
#include <iterator>
#include <initializer_list>
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

/// Bytes in a short human form: "240 GB", "22.9 GB", "512 bytes" (decimal units,
/// three significant digits).
inline std::string human_bytes(std::uint64_t bytes) {
  static constexpr const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  if (bytes < 1000) return std::to_string(bytes) + " bytes";
  double v = static_cast<double>(bytes);
  std::size_t u = 0;
  // Move up while the value would print as 1000 or more at three significant digits.
  while (v >= 999.5 && u + 1 < std::size(units)) {
    v /= 1000.0;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g %s", v, units[u]);
  return buf;
}

/// Throws interpatch::error with a message made of the parts.
template <class... A>
[[noreturn]] void fail(errc code, const A&... parts) {
  throw error(code, cat(parts...));
}

/// Runs f; an error it throws keeps its code and gets `where` and ": " in front of
/// its message (a spec's JSON Pointer, a file and its member).
template <class F>
decltype(auto) prefixed(const std::string& where, F&& f) {
  try {
    return f();
  } catch (const error& e) {
    throw error(e.code(), where + ": " + e.what());
  }
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

/// Refuses caller memory for a batch evaluation whose size is not the product of
/// the parameter counts (an overflowing product matches no buffer).
inline void check_output_size(std::size_t got, std::initializer_list<std::size_t> counts, const char* what) {
  std::size_t want = 1;
  bool overflow = false;
  std::string dims;
  for (std::size_t n : counts) {
    if (n != 0 && want > static_cast<std::size_t>(-1) / n) overflow = true;
    want *= n;
    dims += (dims.empty() ? "" : "x") + std::to_string(n);
  }
  if (overflow || got != want)
    fail(errc::size_mismatch, what, ": the output holds ", got, " points, the ", dims, " grid has ",
         overflow ? std::string("more than can be addressed") : std::to_string(want));
}

/// Refuses a rectangle [i0, i0 + ni) × [j0, j0 + nj) that does not lie in a grid of
/// nu × nv (Surface::NormalGrid).
inline void check_rectangle(std::size_t i0, std::size_t ni, std::size_t j0, std::size_t nj, std::size_t nu,
                            std::size_t nv) {
  if (i0 > nu || ni > nu - i0 || j0 > nv || nj > nv - j0)
    fail(errc::out_of_domain, "rows ", i0, " to ", i0 + ni, " and columns ", j0, " to ", j0 + nj,
         " are beyond the grid of ", nu, "x", nv);
}

}  // namespace interpatch::detail

// Internal invariants: checked in debug builds, compiled out in release.
#ifdef NDEBUG
#define INTERPATCH_ASSERT(cond) ((void)0)
#else
#include <cassert>
#define INTERPATCH_ASSERT(cond) assert(cond)
#endif
