#pragma once
// CRC-32 as ZIP archives use it (ISO 3309, reflected polynomial 0xEDB88320, initial
// and final value inverted): "123456789" gives 0xCBF43926. The .npz writer computes
// it over each member as the bytes go to the file, the reader over the bytes as they
// come from it. Table-driven, eight bytes a step (slicing-by-8), and on large blocks
// every core at once: the checksums of pieces combine into the checksum of the whole
// (crc32_combine), so a block is cut into one piece per thread.

#include <cstddef>
#include <cstdint>

namespace interpatch::io::internal {

/// The CRC-32 of `crc`'s bytes followed by the n bytes at `data` (crc = 0 for a
/// start). Blocks of a few MiB and more are split between the threads.
[[nodiscard]] std::uint32_t crc32(const void* data, std::size_t n, std::uint32_t crc = 0) noexcept;

/// The same on the calling thread only (for callers that are threads of a parallel
/// loop already).
[[nodiscard]] std::uint32_t crc32_serial(const void* data, std::size_t n, std::uint32_t crc = 0) noexcept;

/// The CRC-32 of A followed by B, from crc_a = CRC-32 of A, crc_b = CRC-32 of B (each
/// from 0) and the length of B: work of the order of log(len_b), not len_b.
[[nodiscard]] std::uint32_t crc32_combine(std::uint32_t crc_a, std::uint32_t crc_b, std::uint64_t len_b) noexcept;

}  // namespace interpatch::io::internal
