#pragma once
// What the spec reader and the tests need of the .npz reader and writer beyond
// io/npz.hpp.

#include <cstddef>
#include <filesystem>

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

}  // namespace interpatch::io::internal
