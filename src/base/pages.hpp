#pragma once
// Zeroed memory whose pages are first touched where they are written, for the library's
// large working arrays that are not grids (grids take large_allocator, allocator.hpp).

#include <cstddef>
#include <utility>

namespace interpatch::detail {

/// `bytes` of zeros from calloc (a large block comes fresh from the system, its pages
/// untouched until written), the whole 2 MiB pages within it advised as huge pages.
/// Freed with std::free, which gives a large block straight back to the system.
/// @throws std::bad_alloc.
void* zeroed_huge(std::size_t bytes);

/// n doubles from zeroed_huge, owned.
class ZeroedDoubles {
 public:
  ZeroedDoubles() = default;
  explicit ZeroedDoubles(std::size_t n) : p_(n ? static_cast<double*>(zeroed_huge(n * sizeof(double))) : nullptr), n_(n) {}
  ZeroedDoubles(ZeroedDoubles&& o) noexcept : p_(std::exchange(o.p_, nullptr)), n_(std::exchange(o.n_, 0)) {}
  ZeroedDoubles& operator=(ZeroedDoubles&& o) noexcept {
    ZeroedDoubles gone(std::move(*this));
    p_ = std::exchange(o.p_, nullptr), n_ = std::exchange(o.n_, 0);
    return *this;
  }
  ZeroedDoubles(const ZeroedDoubles& o);
  ZeroedDoubles& operator=(const ZeroedDoubles& o);
  ~ZeroedDoubles();
  [[nodiscard]] double* data() noexcept { return p_; }
  [[nodiscard]] const double* data() const noexcept { return p_; }
  [[nodiscard]] std::size_t size() const noexcept { return n_; }
  [[nodiscard]] bool empty() const noexcept { return n_ == 0; }
  double& operator[](std::size_t k) noexcept { return p_[k]; }
  const double& operator[](std::size_t k) const noexcept { return p_[k]; }
  double* begin() noexcept { return p_; }
  double* end() noexcept { return p_ + n_; }
  /// Gives the whole pages past the first `bytes` back to the system: they read as zero
  /// again, and count in no process's memory until written.
  void let_go_after(std::size_t bytes) noexcept;

 private:
  double* p_ = nullptr;
  std::size_t n_ = 0;
};

}  // namespace interpatch::detail
