#pragma once
/// @file memory.hpp
/// Refusing work too large for this machine before allocating for it.

#include <cstddef>
#include <string_view>

namespace interpatch {

/// Bytes this process may still allocate: the smallest of the memory the system
/// reports available (MemAvailable), the address-space limit (ulimit -v) minus the
/// address space in use, and the room left under a cgroup memory limit (v1 or v2,
/// as in a container), reclaimable page cache counted as free.
std::size_t available_memory() noexcept;

/// Throws error too_large, naming `what`, the bytes needed and the bytes
/// available ("grid needs 240 GB (240000000000 bytes), 22.9 GB available (...)"),
/// when `count` items of `item_bytes` each (overflow-checked) do not fit.
/// Example:
/// @code
///   interpatch::require_memory(k * k, 3 * sizeof(double), "evaluation grid 100000x100000");
/// @endcode
void require_memory(std::size_t count, std::size_t item_bytes, std::string_view what);

}  // namespace interpatch
