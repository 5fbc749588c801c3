// libFuzzer target: CSV text -> io::parse_csv_points (the code path of
// io::read_csv_points). Bad input must end in interpatch::error; anything else
// crashes, and so does a reader that contradicts itself.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>
#include <vector>

#include "interpatch/error.hpp"
#include "interpatch/io/csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<interpatch::Vec3> points;
  try {
    points = interpatch::io::parse_csv_points(text, 0, "fuzz.csv");
  } catch (const interpatch::error&) {
    return 0;  // bad input, reported as it should be
  }
  // Every point is finite, and the count the reader found is the count it accepts.
  for (const auto& p : points)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) std::abort();
  if (points.empty()) return 0;
  const auto again = interpatch::io::parse_csv_points(text, points.size(), "fuzz.csv");
  if (again.size() != points.size() || std::memcmp(again.data(), points.data(), points.size() * sizeof points[0]) != 0)
    std::abort();
  try {
    (void)interpatch::io::parse_csv_points(text, points.size() + 1, "fuzz.csv");
    std::abort();  // one point too many expected must be refused
  } catch (const interpatch::error& e) {
    if (e.code() != interpatch::errc::size_mismatch) std::abort();
  }
  return 0;
}
