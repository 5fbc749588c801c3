// The I/O of blocks: this process's rows of the .npy points, read with MPI-IO and
// converted to doubles in C order, and the few rows of the others it looks at.

#include <algorithm>
#include <bit>
#include <cstring>

#include "base/text.hpp"
#include "interpatch/memory.hpp"
#include "io/spec/reader.hpp"
#include "mpi/driver.hpp"

namespace interpatch::mpi {

using detail::cat;

namespace {

// One value of the file's dtype as a double (float32 widened, byte order swapped).
double file_value(const unsigned char* raw, const io::internal::NpyDtype& dtype) {
  const std::size_t es = dtype.size;
  unsigned char b[8];
  std::memcpy(b, raw, es);
  if (dtype.big_endian != (std::endian::native == std::endian::big)) std::reverse(b, b + es);
  if (es == 8) return std::bit_cast<double>(b);
  float f;
  std::memcpy(&f, b, 4);
  return static_cast<double>(f);
}

// Rows of the .npy file as doubles: rows [r, r + n) of `row` values each, C order.
void read_rows(const InputFile& file, const Plan& plan, std::size_t row, std::size_t r, std::size_t n, double* dst) {
  const std::size_t es = plan.dtype.size, total = row * n;
  if (n == 0) return;
  if (plan.header.fortran_order) {
    // Value q of a row (in the file's order: the first index after u fastest) is a
    // run of the n rows' values, n0 values apart from the next: a strided read of
    // the runs, then each value to its place in C order.
    const auto& shape = plan.header.shape;
    const std::size_t n0 = shape[0];
    const std::size_t group = std::max<std::size_t>(1, (std::size_t{1} << 20) / n);
    std::vector<unsigned char> raw(std::min(group, row) * n * es);
    for (std::size_t q0 = 0; q0 < row; q0 += group) {
      const std::size_t g = std::min(group, row - q0);
      file.read_strided(reinterpret_cast<char*>(raw.data()), g, n * es, std::uint64_t{n0} * es,
                        plan.header.data_offset + (std::uint64_t{r} + std::uint64_t{n0} * q0) * es);
      for (std::size_t q = q0; q < q0 + g; ++q) {
        std::size_t pos = 0, rest = q;  // q's place in a row in C order
        for (std::size_t a = 1; a < shape.size(); ++a) {
          std::size_t later = 1;
          for (std::size_t b = a + 1; b < shape.size(); ++b) later *= shape[b];
          pos += (rest % shape[a]) * later;
          rest /= shape[a];
        }
        for (std::size_t i = 0; i < n; ++i) dst[i * row + pos] = file_value(raw.data() + ((q - q0) * n + i) * es, plan.dtype);
      }
    }
    return;
  }
  const std::uint64_t at = plan.header.data_offset + std::uint64_t{r} * row * es;
  if (es == 8 && !plan.dtype.big_endian && std::endian::native == std::endian::little) {
    file.read(reinterpret_cast<char*>(dst), total * 8, at);
    return;
  }
  constexpr std::size_t piece = std::size_t{1} << 20;
  std::vector<unsigned char> raw(std::min(total, piece) * es);
  for (std::size_t done = 0; done < total; done += piece) {
    const std::size_t k = std::min(piece, total - done);
    file.read(reinterpret_cast<char*>(raw.data()), k * es, at + done * es);
    for (std::size_t i = 0; i < k; ++i) dst[done + i] = file_value(raw.data() + i * es, plan.dtype);
  }
}

// The coordinates of points as doubles (Vec3 is three doubles); null for none, where
// &p->x would dereference nothing.
static_assert(sizeof(Vec3) == 3 * sizeof(double), "points are read and moved as triples of doubles");
double* doubles(Vec3* p) { return reinterpret_cast<double*>(p); }

}  // namespace

template <std::size_t D>
Held<D> read_block(const Plan& plan, const Team& team) {
  Held<D> b;
  std::array<std::size_t, 3>& n = b.n;
  for (std::size_t a = 0; a < D; ++a) n[a] = plan.header.shape[a];
  const std::size_t M = b.row_size();
  // Plain variables, not a structured binding: lambdas capture them (clang 14 refuses bindings).
  const std::pair<std::size_t, std::size_t> block = chunk_block(n[0], team.rank(), team.size());
  const std::size_t first = b.first = block.first, count = b.count = block.second;
  team.run([&] {
    require_memory(count * M, sizeof(Vec3), cat("/points: this process's ", count, " rows of the grid"));
    b.rows.resize(count * M);
    io::reader::at("/points", [&] {
      const InputFile file(plan.points, team);
      read_rows(file, plan, 3 * M, first, count, doubles(b.rows.data()));
      const std::size_t at[5] = {first > 0 ? first - 1 : 0, 0, std::min<std::size_t>(1, n[0] - 1), n[0] < 2 ? 0 : n[0] - 2,
                                 n[0] - 1};
      for (std::size_t h = 0; h < 5; ++h) {
        b.halo[h].resize(M);
        read_rows(file, plan, 3 * M, at[h], 1, doubles(b.halo[h].data()));
      }
    });
  });
  return b;
}

template Held<2> read_block<2>(const Plan&, const Team&);
template Held<3> read_block<3>(const Plan&, const Team&);

}  // namespace interpatch::mpi
