#pragma once
/// @file grid.hpp
/// A dense array of rank 1, 2 or 3 in C order (first index slowest): the shape of
/// every grid of points interpatch reads and writes, first index along u.

#include <array>
#include <cstddef>
#include <vector>

#include "interpatch/allocator.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch {

/// Tag of the Grid constructor for outputs: elements zero, and a large grid's pages
/// are left untouched until written, so threads that fill their own parts also
/// take the cost of the fresh pages in parallel.
struct zeroed_t {
  explicit zeroed_t() = default;
};
inline constexpr zeroed_t zeroed{};

/// Tag of the Grid constructor for outputs the caller overwrites whole: elements
/// unspecified until written, and a large grid may take the touched pages of one
/// freed before (see resize_for_overwrite).
struct for_overwrite_t {
  explicit for_overwrite_t() = default;
};
inline constexpr for_overwrite_t for_overwrite{};

/// Dense rank-`Rank` array in C order. `Grid<Vec3, 2>` of shape {n+1, m+1} holds
/// the points Q[p][q], p along u, q along v.
///
/// Example:
/// @code
///   interpatch::PointGrid g({4, 5});
///   g(3, 4) = {1, 2, 3};
/// @endcode
template <class T, std::size_t Rank>
class Grid {
 public:
  using shape_type = std::array<std::size_t, Rank>;
  using storage_type = std::vector<T, large_allocator<T>>;

  Grid() { shape_.fill(0); }
  explicit Grid(const shape_type& shape, const T& fill = T{}) : shape_(shape), data_(count(shape), fill) {}
  /// Takes `data` in C order; its size must be the product of the shape.
  Grid(const shape_type& shape, storage_type data) : shape_(shape), data_(std::move(data)) {}
  Grid(const shape_type& shape, const std::vector<T>& data) : shape_(shape), data_(data.begin(), data.end()) {}
  /// Zero elements (for T whose zero value is all zero bits: numbers and aggregates
  /// of them).
  Grid(const shape_type& shape, zeroed_t) : shape_(shape) { resize_zeroed(data_, count(shape)); }
  /// Elements to be overwritten, every one, before they are read (trivially
  /// copyable T).
  Grid(const shape_type& shape, for_overwrite_t) : shape_(shape) { resize_for_overwrite(data_, count(shape)); }

  [[nodiscard]] const shape_type& shape() const noexcept { return shape_; }
  [[nodiscard]] std::size_t extent(std::size_t axis) const noexcept { return shape_[axis]; }
  [[nodiscard]] std::size_t size() const noexcept { return data_.size(); }
  [[nodiscard]] bool empty() const noexcept { return data_.empty(); }

  template <class... I>
  T& operator()(I... i) noexcept { return data_[offset(i...)]; }
  template <class... I>
  const T& operator()(I... i) const noexcept { return data_[offset(i...)]; }

  [[nodiscard]] T* data() noexcept { return data_.data(); }
  [[nodiscard]] const T* data() const noexcept { return data_.data(); }
  [[nodiscard]] const storage_type& values() const noexcept { return data_; }
  [[nodiscard]] storage_type& values() noexcept { return data_; }

  static std::size_t count(const shape_type& shape) noexcept {
    std::size_t n = 1;
    for (auto e : shape) n *= e;
    return n;
  }

 private:
  template <class... I>
  [[nodiscard]] std::size_t offset(I... i) const noexcept {
    static_assert(sizeof...(I) == Rank, "one index per axis");
    const std::array<std::size_t, Rank> idx{static_cast<std::size_t>(i)...};
    std::size_t off = 0;
    for (std::size_t a = 0; a < Rank; ++a) off = off * shape_[a] + idx[a];
    return off;
  }

  shape_type shape_;
  storage_type data_;
};

/// (n+1) × (m+1) points, first index along u.
using PointGrid = Grid<Vec3, 2>;
/// (n+1) × (m+1) × (l+1) points, indices along u, v, w.
using PointGrid3 = Grid<Vec3, 3>;

}  // namespace interpatch
