#include "base/pages.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <mutex>

#include "interpatch/allocator.hpp"

namespace interpatch::detail {

namespace {
constexpr std::size_t huge = std::size_t{2} << 20;
std::size_t rounded(std::size_t bytes) noexcept { return (bytes + huge - 1) / huge * huge; }

// Mappings given back and kept for reuse: a batch evaluation repeated on grids of
// one size then writes into pages it touched before instead of fresh ones, whose
// first touch (the kernel zeroing them, the hypervisor backing them) costs more
// than the evaluation's own writes on a virtual machine. The most recently given
// back are kept: a new one pushes out the oldest when the slots or the bytes run out.
constexpr std::size_t keep_limit = std::size_t{256} << 20;  // bytes kept in all
struct Kept {
  void* p = nullptr;
  std::size_t size = 0;
  std::uint64_t age = 0;  // when it was given back
};
std::mutex kept_mutex;
std::array<Kept, 4> kept;
std::size_t kept_bytes = 0;
std::uint64_t kept_clock = 0;

void* take_kept(std::size_t size) noexcept {
  const std::lock_guard<std::mutex> lock(kept_mutex);
  for (Kept& k : kept)
    if (k.p != nullptr && k.size == size) {
      void* p = k.p;
      k = {};
      kept_bytes -= size;
      return p;
    }
  return nullptr;
}

bool keep(void* p, std::size_t size) noexcept {
  if (size > keep_limit) return false;
  const std::lock_guard<std::mutex> lock(kept_mutex);
  for (;;) {
    Kept* free_slot = nullptr;
    Kept* oldest = nullptr;
    for (Kept& k : kept) {
      if (k.p == nullptr) free_slot = &k;
      else if (oldest == nullptr || k.age < oldest->age) oldest = &k;
    }
    if (free_slot != nullptr && kept_bytes + size <= keep_limit) {
      *free_slot = {p, size, ++kept_clock};
      kept_bytes += size;
      return true;
    }
    ::munmap(oldest->p, oldest->size);  // not null: the slots or the bytes are full
    kept_bytes -= oldest->size;
    *oldest = {};
  }
}
}  // namespace

void* map_pages(std::size_t bytes, bool zero) {
  const std::size_t size = rounded(bytes);
  if (size < bytes) throw std::bad_alloc();
  if (!zero)
    if (void* p = take_kept(size)) return p;
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

void unmap_pages(void* p, std::size_t bytes) noexcept {
  const std::size_t size = rounded(bytes);
  if (!keep(p, size)) ::munmap(p, size);
}

void* zeroed_huge(std::size_t bytes) {
  void* p = std::calloc(bytes, 1);
  if (p == nullptr) throw std::bad_alloc();
  const auto base = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t first = (base + huge - 1) / huge * huge, last = (base + bytes) / huge * huge;
  if (last > first) ::madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);  // advice only
  return p;
}

ZeroedDoubles::ZeroedDoubles(const ZeroedDoubles& o) : ZeroedDoubles(o.n_) { std::copy(o.p_, o.p_ + o.n_, p_); }

ZeroedDoubles& ZeroedDoubles::operator=(const ZeroedDoubles& o) {
  if (this != &o) *this = ZeroedDoubles(o);
  return *this;
}

ZeroedDoubles::~ZeroedDoubles() { std::free(p_); }

void ZeroedDoubles::let_go_after(std::size_t bytes) noexcept {
  constexpr std::uintptr_t page = 4096;
  const auto base = reinterpret_cast<std::uintptr_t>(p_);
  const std::uintptr_t first = (base + bytes + page - 1) / page * page, last = (base + n_ * sizeof(double)) / page * page;
  // Within the block, whichever way calloc made it: the allocator keeps nothing in the
  // bytes it handed out.
  if (last > first) ::madvise(reinterpret_cast<void*>(first), last - first, MADV_DONTNEED);
}

}  // namespace interpatch::detail
