#pragma once
// Small specs the command-line tests share.

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

}  // namespace interpatch::test
