#include <sys/mman.h>

#include <cstdint>

#include "interpatch/allocator.hpp"

namespace interpatch::detail {

namespace {
constexpr std::size_t huge = std::size_t{2} << 20;
std::size_t rounded(std::size_t bytes) noexcept { return (bytes + huge - 1) / huge * huge; }
}  // namespace

void* map_pages(std::size_t bytes) {
  const std::size_t size = rounded(bytes);
  if (size < bytes) throw std::bad_alloc();
  // Map one huge page more than needed, then trim to a 2 MiB-aligned window so
  // every page of the buffer can be a huge page.
  void* raw = ::mmap(nullptr, size + huge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const auto base = reinterpret_cast<std::uintptr_t>(raw);
  const std::uintptr_t aligned = (base + huge - 1) / huge * huge;
  if (aligned > base) ::munmap(raw, aligned - base);
  const std::uintptr_t end = base + size + huge;
  if (end > aligned + size) ::munmap(reinterpret_cast<void*>(aligned + size), end - (aligned + size));
  void* p = reinterpret_cast<void*>(aligned);
  ::madvise(p, size, MADV_HUGEPAGE);  // advice only: without THP the mapping still works
  return p;
}

void unmap_pages(void* p, std::size_t bytes) noexcept { ::munmap(p, rounded(bytes)); }

}  // namespace interpatch::detail
