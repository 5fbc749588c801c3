// Writing .npy files: the values as little-endian float64 (an .npz member's too),
// and the arrays of write_npy and write_npy_rows, the latter made a block at a
// time by every thread while the block before is written.

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "base/pipeline.hpp"
#include "base/text.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/memory.hpp"
#include "io/crc32.hpp"
#include "io/finite.hpp"
#include "io/npy_bytes.hpp"
#include "io/npy_format.hpp"

namespace interpatch::io {
namespace fs = std::filesystem;

namespace {

using internal::crc32;
using internal::npy_shape_text;
using internal::npy_io::byteswap;

}  // namespace

namespace internal {

void write_values(std::ostream& os, const double* data, std::size_t n, std::uint32_t* crc) {
  const auto put = [&](const void* bytes, std::size_t count) {
    if (crc) *crc = crc32(bytes, count, *crc);
    os.write(static_cast<const char*>(bytes), static_cast<std::streamsize>(count));
  };
  if constexpr (std::endian::native == std::endian::little) {
    // With a checksum, in pieces of 8 MiB: each is summed (by every thread) and
    // written while it is still in the cache. Without, all at once.
    const std::size_t step = crc ? std::size_t{1} << 20 : std::max<std::size_t>(n, 1);
    for (std::size_t done = 0; done < n; done += step) put(data + done, std::min(step, n - done) * sizeof(double));
  } else {
    std::vector<std::uint64_t> chunk(std::min<std::size_t>(n, std::size_t{1} << 16));
    for (std::size_t done = 0; done < n;) {
      const std::size_t k = std::min(chunk.size(), n - done);
      for (std::size_t i = 0; i < k; ++i) chunk[i] = byteswap(std::bit_cast<std::uint64_t>(data[done + i]));
      put(chunk.data(), k * 8);
      done += k;
    }
  }
}

}  // namespace internal

namespace {


// The array's element count, refused when the shape overflows.
std::size_t element_count(const fs::path& path, const std::vector<std::size_t>& dims) {
  std::size_t count = 1;
  for (std::size_t d : dims) {
    if (d != 0 && count > std::numeric_limits<std::size_t>::max() / d)
      detail::fail(errc::size_mismatch, "cannot write '", path.string(), "': shape ", npy_shape_text(dims), " overflows");
    count *= d;
  }
  return count;
}

}  // namespace

void write_npy(const fs::path& path, std::span<const std::size_t> shape, std::span<const double> data) {
  const std::vector<std::size_t> dims(shape.begin(), shape.end());
  if (const std::size_t count = element_count(path, dims); count != data.size())
    detail::fail(errc::size_mismatch, "cannot write '", path.string(), "': shape ", npy_shape_text(dims), " has ", count,
                 " elements, data has ", data.size());
  // The data in one block, the caller's memory as it is.
  write_npy(path, shape, std::max<std::size_t>(data.size(), 1),
            [&](std::size_t first, std::size_t count) { return data.subspan(first, count); });
}

void write_npy(const fs::path& path, std::span<const std::size_t> shape, std::size_t block,
               const NpyProducer& produce) {
  const std::vector<std::size_t> dims(shape.begin(), shape.end());
  const std::size_t count = element_count(path, dims);
  if (block == 0) detail::fail(errc::size_mismatch, "cannot write '", path.string(), "': blocks of 0 values");
  const std::string header = internal::npy_header("<f8", dims);
  // The file's size, for write_atomically to allocate at once; 0 (unknown) for a
  // shape whose bytes cannot be counted, which the writes then refuse.
  const std::uintmax_t bytes = count <= (std::numeric_limits<std::uintmax_t>::max() - header.size()) / sizeof(double)
                                   ? header.size() + count * sizeof(double)
                                   : 0;
  write_atomically(path, [&](std::ostream& os) {
    os.write(header.data(), static_cast<std::streamsize>(header.size()));
    for (std::size_t first = 0; first < count; first += block) {
      const std::size_t n = std::min(block, count - first);
      const std::span<const double> values = produce(first, n);
      if (values.size() != n)
        detail::fail(errc::size_mismatch, "cannot write '", path.string(), "': values ", first, " to ", first + n - 1,
                     " came as ", values.size(), " values");
      internal::write_values(os, values.data(), n);
    }
  }, bytes);
}

namespace {

// About 2^17 values (1 MiB) a block of write_npy_rows, in pieces of about 2^13 for
// the threads to share: still in the cache when it is written, and few fresh pages
// (on the machine of docs/BENCHMARKS.md blocks of 4 MiB cost more in page faults
// than the overlap gains). At least 2 rows a block, so that the threads share rows
// as large as a volume's.
std::size_t block_rows_of(std::size_t per_row) {
  return std::max<std::size_t>(2, (std::size_t{1} << 17) / std::max<std::size_t>(per_row, 1));
}
std::size_t piece_rows_of(std::size_t per_row) {
  return std::max<std::size_t>(1, (std::size_t{1} << 13) / std::max<std::size_t>(per_row, 1));
}

}  // namespace

std::size_t write_npy_rows_held(std::size_t rows, std::size_t per_row) noexcept {
  const std::size_t n = std::min(block_rows_of(per_row), rows);
  return per_row != 0 && n > std::numeric_limits<std::size_t>::max() / 2 / per_row ? std::numeric_limits<std::size_t>::max()
                                                                                    : 2 * n * per_row;
}

void write_npy_rows(const fs::path& path, std::span<const std::size_t> shape, const NpyRowsMaker& make,
                    const progress_callback& progress) {
  const std::vector<std::size_t> dims(shape.begin(), shape.end());
  if (dims.empty()) detail::fail(errc::size_mismatch, "cannot write '", path.string(), "' by rows: the shape has no axis");
  const std::size_t count = element_count(path, dims);
  const std::size_t rows = dims[0], per_row = rows == 0 ? 0 : count / rows;
  const std::size_t block_rows = block_rows_of(per_row), piece_rows = piece_rows_of(per_row);
  // The first block is an eighth of the others: nothing is written until it is made,
  // with the first touches of its pages; every block after it is made while the one
  // before is written.
  const std::size_t first_rows = std::min(rows, std::max<std::size_t>(1, block_rows / 8));
  const std::size_t blocks = rows == 0 ? 0 : 1 + (rows - first_rows + block_rows - 1) / block_rows;
  const std::string header = internal::npy_header("<f8", dims);
  const std::uintmax_t bytes = count <= (std::numeric_limits<std::uintmax_t>::max() - header.size()) / sizeof(double)
                                   ? header.size() + count * sizeof(double)
                                   : 0;
  require_memory(write_npy_rows_held(rows, per_row), sizeof(double), "the blocks of '" + path.string() + "'");
  const std::size_t held = std::min(block_rows, rows) * per_row;
  // Not zeroed: the threads' first writes touch the pages.
  const std::unique_ptr<double[]> buffers[2] = {std::make_unique_for_overwrite<double[]>(held),
                                                std::make_unique_for_overwrite<double[]>(held)};
  const auto block_span = [&](std::size_t b) {
    if (b == 0) return std::pair(std::size_t{0}, first_rows);
    const std::size_t r0 = first_rows + (b - 1) * block_rows;
    return std::pair(r0, std::min(block_rows, rows - r0));
  };
  write_atomically(path, [&](std::ostream& os) {
    os.write(header.data(), static_cast<std::streamsize>(header.size()));
    detail::pipeline(
        blocks, count >= detail::parallel_min_work / 4,
        [&](std::size_t b) { return (block_span(b).second + piece_rows - 1) / piece_rows; },
        [&](std::size_t b, std::size_t p) {
          const auto [r0, n] = block_span(b);
          const std::size_t first = p * piece_rows, k = std::min(piece_rows, n - first);
          make(r0 + first, k, std::span<double>(buffers[b % 2].get() + first * per_row, k * per_row));
        },
        [&](std::size_t b) {
          const auto [r0, n] = block_span(b);
          internal::require_finite(buffers[b % 2].get(), n * per_row, r0 * per_row, dims, "'" + path.string() + "'");
          internal::write_values(os, buffers[b % 2].get(), n * per_row);
          if (progress) progress(static_cast<double>(r0 + n) / static_cast<double>(rows));
        });
  }, bytes);
}

}  // namespace interpatch::io
