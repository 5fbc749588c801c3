#pragma once
// Points (or rays) from a file a block at a time, so that a file of any length is
// read in the memory of one block: a .npy of float32 or float64 (either byte order)
// whose shape ends in 3 (points) or in (2, 3) (rays: origin, direction), or a .csv of
// 3 (or 6) numbers a line.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/npy_format.hpp"

namespace interpatch::io::internal {

class RowReader {
 public:
  /// width: numbers a row (3 or 6). what: "points" or "rays", for messages.
  /// @throws error file_unreadable, malformed_file (naming the file and what is
  ///   wrong: the dtype, the shape, the line and field of a CSV).
  RowReader(const std::filesystem::path& path, std::size_t width, std::string what);
  /// Rows in all.
  [[nodiscard]] std::size_t count() const noexcept { return count_; }
  /// The array's shape without the numbers of a row ((N,) for a CSV).
  [[nodiscard]] const std::vector<std::size_t>& shape() const noexcept { return shape_; }
  /// The next rows, at most `rows`, into dst (width doubles a row); how many.
  /// @throws error file_unreadable, malformed_file.
  std::size_t read(double* dst, std::size_t rows);

 private:
  std::size_t csv_rows(double* dst, std::size_t rows);
  std::filesystem::path path_;
  std::string name_;
  std::size_t width_;
  std::ifstream in_;
  bool csv_ = false;
  NpyDtype dtype_;
  std::vector<std::size_t> shape_;
  std::size_t count_ = 0, done_ = 0, line_ = 0;
  std::vector<unsigned char> bytes_;
};

}  // namespace interpatch::io::internal
