#pragma once
// Output in bounded chunks for the mesh writers: text and binary values are
// gathered in a buffer of about a megabyte and handed to the stream, so no file is
// ever built in memory; write_records makes a file's list of records on every
// thread while one thread writes.

#include <algorithm>
#include <array>
#include <bit>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "base/pipeline.hpp"

namespace interpatch::io::internal::mesh_io {

// Native doubles turned in place into the given byte order.
inline void to_byte_order(char* bytes, std::size_t size, std::endian order) {
  if (order == std::endian::native) return;
  for (std::size_t d = 0; d + sizeof(std::uint64_t) <= size; d += sizeof(std::uint64_t)) {
    std::uint64_t w;
    std::memcpy(&w, bytes + d, sizeof w);
    w = __builtin_bswap64(w);
    std::memcpy(bytes + d, &w, sizeof w);
  }
}

class Sink {
 public:
  /// Gathers about a megabyte, then hands it to the stream.
  explicit Sink(std::ostream& os) : os_(&os), buf_(&own_) { own_.reserve(limit + 256); }
  /// Appends to `out` and never flushes: a piece of a file made on a thread of its own.
  explicit Sink(std::string& out) : buf_(&out) {}
  Sink(const Sink&) = delete;
  Sink& operator=(const Sink&) = delete;
  ~Sink() = default;

  void flush() {
    if (!os_) return;
    os_->write(buf_->data(), static_cast<std::streamsize>(buf_->size()));
    buf_->clear();
  }

  Sink& text(std::string_view s) {
    *buf_ += s;
    maybe_flush();
    return *this;
  }
  Sink& ch(char c) {
    *buf_ += c;
    return *this;
  }
  Sink& uint(std::uint64_t v) {
    char b[24];
    const auto r = std::to_chars(b, b + sizeof b, v);
    buf_->append(b, r.ptr);
    return *this;
  }
  /// Shortest text that reads back as the same double.
  Sink& shortest(double v) {
    char b[32];
    const auto r = std::to_chars(b, b + sizeof b, v);
    buf_->append(b, r.ptr);
    return *this;
  }
  template <class T>
  Sink& little(T v) {
    return bytes(v, std::endian::little);
  }
  template <class T>
  Sink& big(T v) {
    return bytes(v, std::endian::big);
  }
  /// Values (points, three doubles each, or doubles) p[0], p[stride], ..., n of
  /// them, in the given byte order.
  template <class T>
  Sink& gather(const T* p, std::size_t n, std::size_t stride, std::endian order) {
    const std::size_t at = buf_->size();
    buf_->resize(at + n * sizeof(T));
    char* to = buf_->data() + at;
    for (std::size_t i = 0; i < n; ++i) std::memcpy(to + i * sizeof(T), p + i * stride, sizeof(T));
    to_byte_order(to, n * sizeof(T), order);
    maybe_flush();
    return *this;
  }

 private:
  template <class T>
  Sink& bytes(T v, std::endian order) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (order != std::endian::native) std::reverse(b, b + sizeof(T));
    buf_->append(b, sizeof(T));
    return *this;
  }
  void maybe_flush() {
    if (os_ && buf_->size() >= limit) flush();
  }

  static constexpr std::size_t limit = std::size_t{1} << 20;
  std::ostream* os_ = nullptr;
  std::string own_;
  std::string* buf_;
};

/// Writes records 0 .. count − 1 to `os` in order, record(sink, r) putting record r
/// into the sink: the bytes of that loop; returns how many bytes that was. Every
/// thread turns a block of records into bytes, a piece of about 64 KiB each into a
/// buffer of its own, while one thread writes the block before (detail::pipeline):
/// text and packed binary cost more to make than to write. `record_bytes` is about
/// what one record takes.
template <class Record>
std::uint64_t write_records(std::ostream& os, std::size_t count, std::size_t record_bytes, Record&& record) {
  constexpr std::size_t piece_bytes = std::size_t{1} << 16, block_pieces = 16;
  const std::size_t per_piece = std::max<std::size_t>(1, piece_bytes / std::max<std::size_t>(1, record_bytes));
  const std::size_t per_block = per_piece * block_pieces;
  const std::size_t blocks = (count + per_block - 1) / per_block;
  // Two blocks of pieces alive at once: block b's in buffers[b % 2].
  std::array<std::vector<std::string>, 2> buffers;
  for (auto& b : buffers) b.resize(block_pieces);
  const auto pieces = [&](std::size_t b) {
    const std::size_t left = count - b * per_block;
    return std::min(block_pieces, (left + per_piece - 1) / per_piece);
  };
  const auto make = [&](std::size_t b, std::size_t p) {
    // The piece grows in a string of this thread's own (its memory taken over from the
    // buffer): the buffers' string objects share cache lines, and every character
    // appended updates its string's size.
    std::string out;
    out.swap(buffers[b % 2][p]);
    out.clear();
    {
      Sink s(out);
      const std::size_t first = b * per_block + p * per_piece, last = std::min(count, first + per_piece);
      for (std::size_t r = first; r < last; ++r) record(s, r);
    }
    out.swap(buffers[b % 2][p]);
  };
  std::uint64_t written = 0;
  const auto write = [&](std::size_t b) {
    const std::size_t n = pieces(b);
    for (std::size_t p = 0; p < n; ++p) {
      const std::string& out = buffers[b % 2][p];
      os.write(out.data(), static_cast<std::streamsize>(out.size()));
      written += out.size();
    }
  };
  detail::pipeline(blocks, count * record_bytes >= 4 * piece_bytes, pieces, make, write);
  return written;
}

}  // namespace interpatch::io::internal::mesh_io
