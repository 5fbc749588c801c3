#pragma once
/// @file allocator.hpp
/// The allocator behind every grid (Grid's storage), and the two ways to size a grid
/// the library's outputs use: zeroed and to be overwritten. Nothing here is needed
/// to use interpatch; it is public because Grid's storage type names it.

#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace interpatch {

namespace detail {
/// Buffers at least this large are mapped directly.
inline constexpr std::size_t large_buffer_bytes = std::size_t{1} << 20;
/// At least `bytes` of memory from the system (src/base/pages.cpp). With `zero`,
/// fresh and zero-filled; without, possibly memory given back before, its contents
/// whatever they were.
/// @throws std::bad_alloc.
void* map_pages(std::size_t bytes, bool zero = true);
/// Gives a mapping back. A few of the most recent ones, up to 256 MiB in all, are
/// kept for map_pages(bytes, false) of the same size; the others are unmapped.
void unmap_pages(void* p, std::size_t bytes) noexcept;

/// How the elements of a large buffer start: constructed (values), as the fresh
/// zero pages of a new mapping (zero_pages), or as they are, to be overwritten by
/// the caller (overwrite). Set on a thread by resize_zeroed and resize_for_overwrite.
enum class Start { values, zero_pages, overwrite };
inline thread_local Start start = Start::values;
}  // namespace detail

/// A std::allocator drop-in that takes large buffers from the system directly, so
/// that a large grid's memory is first touched by the threads that write it.
template <class T>
struct large_allocator {
  using value_type = T;
  large_allocator() noexcept = default;
  template <class U>
  large_allocator(const large_allocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    // Only zero pages must be fresh: constructed elements and overwritten ones may
    // reuse a mapping whose pages are touched already.
    if (bytes >= detail::large_buffer_bytes)
      return static_cast<T*>(detail::map_pages(bytes, detail::start == detail::Start::zero_pages));
    return std::allocator<T>().allocate(n);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    const std::size_t bytes = n * sizeof(T);
    if (bytes >= detail::large_buffer_bytes) detail::unmap_pages(p, bytes);
    else std::allocator<T>().deallocate(p, n);
  }
  /// Value-initialization of an element while detail::start is zero_pages or
  /// overwrite does nothing: the mapping is already zero, or the caller writes every
  /// element; pages are first touched by whoever writes.
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    if constexpr (sizeof...(Args) == 0)
      if (detail::start != detail::Start::values) return;
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  friend bool operator==(const large_allocator&, const large_allocator<U>&) noexcept { return true; }
};

namespace detail {
// Resizes an empty vector to n elements that start as `how` says.
template <class T>
void resize_started(std::vector<T, large_allocator<T>>& v, std::size_t n, Start how) {
  static_assert(std::is_trivially_copyable_v<T>, "only trivially copyable values can start unconstructed");
  if (!v.empty() || n * sizeof(T) < large_buffer_bytes) {  // from operator new: constructed
    v.resize(n);
    return;
  }
  struct Guard {
    explicit Guard(Start s) noexcept { start = s; }
    ~Guard() { start = Start::values; }
  } guard(how);
  v.resize(n);
}
}  // namespace detail

/// Resizes an empty vector that uses large_allocator to n zero elements (for T whose
/// zero value is all zero bits: numbers and aggregates of them), leaving the pages
/// of a large buffer untouched until they are written.
template <class T>
void resize_zeroed(std::vector<T, large_allocator<T>>& v, std::size_t n) {
  detail::resize_started(v, n, detail::Start::zero_pages);
}

/// Resizes an empty vector that uses large_allocator to n elements the caller will
/// all overwrite (trivially copyable T): a large buffer may reuse the memory of one
/// freed before instead of fresh memory. Small buffers are value-initialized.
template <class T>
void resize_for_overwrite(std::vector<T, large_allocator<T>>& v, std::size_t n) {
  detail::resize_started(v, n, detail::Start::overwrite);
}

}  // namespace interpatch
