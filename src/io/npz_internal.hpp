#pragma once
// What the spec reader and the tests need of the .npz reader and writer beyond
// io/npz.hpp.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <ostream>
#include <vector>
#include <span>
#include <string>

#include "interpatch/io/spec.hpp"

namespace interpatch::io::internal {

/// read_exact_npz of an archive that must hold a surface (dims 2) or a volume
/// (dims 3): one of the other kind is refused (wrong_type) from its degree member,
/// before its net is read.
[[nodiscard]] ExactForm read_exact_npz(const std::filesystem::path& path, std::size_t dims);

/// write_exact_npz with ZIP64 records for every member and for the archive whatever
/// their sizes (`zip64`), or only where a size or an offset passes 4 GiB: the
/// tests' way to the ZIP64 records without writing 4 GiB.
void write_exact_npz(const std::filesystem::path& path, const ExactForm& exact, bool zip64);

/// The bytes of an .npz archive of a polynomial exact form (degrees, knots, a
/// control net of `shape` without its 3 coordinates) other than the control points'
/// data, for a writer that puts those in place itself (a run split between
/// processes, src/mpi/): `head` is every byte before them, `tail` every byte after,
/// and the data go at points_offset (head.size()); total is the archive's size.
/// `points_crc` is the CRC-32 of the data alone (crc32_combine of the pieces). The
/// archive is write_exact_npz's, byte for byte.
struct NpzFrame {
  std::string head, tail;
  std::uint64_t points_offset = 0, total = 0;
};
[[nodiscard]] NpzFrame exact_npz_frame(std::span<const int> degrees, std::span<const KnotVector* const> knots,
                                       std::span<const std::size_t> shape, std::uint32_t points_crc);

/// An .npz archive of members whose sizes are known before their data (a dtype and
/// a shape each): every member has its place in the file from the start, so pieces
/// of different members can be written in any interleaving, each member's in order
/// (a run that makes a row of every array at a time, streamed). The stream must
/// seek (io::write_atomically's does).
class NpzColumns {
 public:
  struct Member {
    std::string name;   ///< without ".npy"
    std::string descr;  ///< "<f8", "|b1", "<i8"
    std::vector<std::size_t> shape;
  };
  explicit NpzColumns(const std::vector<Member>& members);
  ~NpzColumns();
  NpzColumns(const NpzColumns&) = delete;
  NpzColumns& operator=(const NpzColumns&) = delete;
  /// The archive's size in bytes.
  [[nodiscard]] std::uint64_t total() const;
  /// Every member's headers.
  void begin(std::ostream& os);
  /// The next n bytes of a member's data.
  void append(std::ostream& os, std::size_t member, const void* bytes, std::size_t n);
  /// The checksums and the directory. @throws error internal when a member did not
  /// get all its bytes.
  void finish(std::ostream& os);

 private:
  struct Impl;
  std::unique_ptr<Impl> i_;
};

}  // namespace interpatch::io::internal
