#pragma once
// Small specs the command-line tests share, and the closed (periodic) data the spec,
// output and command-line tests build from.

#include <cmath>
#include <cstddef>
#include <numbers>

#include <nlohmann/json.hpp>

namespace interpatch::test {

/// The curve {"line": [a, b]}.
inline nlohmann::json line_curve(const nlohmann::json& a, const nlohmann::json& b) { return {{"line", {a, b}}}; }

/// A Coons patch of four lines over the unit square with z = u v: the bilinear
/// patch of its corners.
inline nlohmann::json square_coons() {
  return {{"type", "coons"},
          {"boundary",
           {{"v0", line_curve({0, 0, 0}, {1, 0, 0})},
            {"v1", line_curve({0, 1, 0}, {1, 1, 1})},
            {"u0", line_curve({0, 0, 0}, {0, 1, 0})},
            {"u1", line_curve({1, 0, 0}, {1, 1, 1})}}}};
}

/// Point k of n around a section of a pipe bent through a quarter turn of radius 3,
/// at s in [0, 1] along it, `thickness` from 0 (the inner wall) to 1 (the outer):
/// the section's radius swells from 0.5 to 0.8 in the middle and it is a little
/// elliptic, so that no two sections and no two points around one are alike.
inline nlohmann::json pipe_point(double s, std::size_t k, std::size_t n, double thickness = 0) {
  const double pi = std::numbers::pi, a = 0.5 * pi * s, phi = 2 * pi * static_cast<double>(k) / static_cast<double>(n);
  const double r = 0.5 + 0.3 * std::sin(pi * s) + 0.2 * thickness;
  const double x = r * std::cos(phi), y = 0.8 * r * std::sin(phi);  // across the bend, along the y axis
  return {3 * std::sin(a) - x * std::sin(a), y, 3 * (1 - std::cos(a)) + x * std::cos(a)};
}

/// A pipe's data: `nu` sections (u along the pipe) of `nv` distinct points (v around
/// it), and with `closing` one more point per section repeating its first exactly.
inline nlohmann::json pipe_points(std::size_t nu, std::size_t nv, bool closing) {
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t i = 0; i < nu; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (std::size_t k = 0; k < nv; ++k) row.push_back(pipe_point(static_cast<double>(i) / static_cast<double>(nu - 1), k, nv));
    if (closing) row.push_back(row[0]);
    rows.push_back(std::move(row));
  }
  return rows;
}

/// {"type": "interpolate"} through pipe_points, "periodic": [false, true] when
/// `periodic` (and no "periodic" otherwise).
inline nlohmann::json pipe_spec(std::size_t nu, std::size_t nv, bool closing, bool periodic = true) {
  nlohmann::json spec = {{"type", "interpolate"}, {"points", pipe_points(nu, nv, closing)}};
  if (periodic) spec["periodic"] = {false, true};
  return spec;
}

/// The wall of the pipe as a volume grid: `nt` layers through the wall (u), `nv`
/// distinct points around (v, and a closing one with `closing`), `nw` sections
/// along (w); {"type": "interpolate_volume"}, "periodic": [false, true, false].
inline nlohmann::json tube_spec(std::size_t nt, std::size_t nv, std::size_t nw, bool closing, bool periodic = true) {
  nlohmann::json g = nlohmann::json::array();
  for (std::size_t i = 0; i < nt; ++i) {
    nlohmann::json slab = nlohmann::json::array();
    for (std::size_t k = 0; k < nv + (closing ? 1 : 0); ++k) {
      nlohmann::json line = nlohmann::json::array();
      for (std::size_t l = 0; l < nw; ++l)
        line.push_back(pipe_point(static_cast<double>(l) / static_cast<double>(nw - 1), k % nv, nv,
                                  static_cast<double>(i) / static_cast<double>(nt - 1)));
      slab.push_back(std::move(line));
    }
    g.push_back(std::move(slab));
  }
  nlohmann::json spec = {{"type", "interpolate_volume"}, {"points", g}};
  if (periodic) spec["periodic"] = {false, true, false};
  return spec;
}

}  // namespace interpatch::test
