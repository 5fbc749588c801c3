#pragma once
/// @file allocator.hpp
/// The allocator behind every grid: large buffers come straight from the system in
/// 2 MiB-aligned mappings marked for transparent huge pages, small ones from
/// operator new. Touching fresh memory page by page is a large share of the cost
/// of a pass over a big grid; huge pages cut the number of page faults 512-fold.

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
/// A zero-filled, 2 MiB-aligned anonymous mapping of at least `bytes`.
/// @throws std::bad_alloc.
void* map_pages(std::size_t bytes);
void unmap_pages(void* p, std::size_t bytes) noexcept;
/// Set on a thread while a Grid takes fresh zero pages for its elements: the
/// allocator then leaves value-initialized elements of large buffers as mapped.
inline thread_local bool leave_zero_pages = false;
}  // namespace detail

/// A std::allocator drop-in that maps large buffers with huge pages.
template <class T>
struct large_allocator {
  using value_type = T;
  large_allocator() noexcept = default;
  template <class U>
  large_allocator(const large_allocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (bytes >= detail::large_buffer_bytes) return static_cast<T*>(detail::map_pages(bytes));
    return std::allocator<T>().allocate(n);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    const std::size_t bytes = n * sizeof(T);
    if (bytes >= detail::large_buffer_bytes) detail::unmap_pages(p, bytes);
    else std::allocator<T>().deallocate(p, n);
  }
  /// Value-initialization of an element of a large buffer while
  /// detail::leave_zero_pages is set does nothing: the mapping is already zero,
  /// and its pages are first touched by whoever writes the element.
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    if constexpr (sizeof...(Args) == 0)
      if (detail::leave_zero_pages) return;
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  friend bool operator==(const large_allocator&, const large_allocator<U>&) noexcept { return true; }
};

/// Resizes an empty vector that uses large_allocator to n zero elements (for T whose
/// zero value is all zero bits: numbers and aggregates of them), leaving the pages
/// of a large buffer untouched until they are written.
template <class T>
void resize_zeroed(std::vector<T, large_allocator<T>>& v, std::size_t n) {
  static_assert(std::is_trivially_copyable_v<T>, "zero pages hold values of trivially copyable types only");
  if (!v.empty() || n * sizeof(T) < detail::large_buffer_bytes) {  // from operator new: not zero
    v.resize(n);
    return;
  }
  struct Guard {
    Guard() noexcept { detail::leave_zero_pages = true; }
    ~Guard() { detail::leave_zero_pages = false; }
  } guard;
  v.resize(n);
}

}  // namespace interpatch
