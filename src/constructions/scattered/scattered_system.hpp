#pragma once
// The normal equations of a scattered fit on a net of knots over a rectangle: a symmetric banded matrix of the control net (the data term, assembled in
// one pass over the points, and the thin-plate fairness term), with its right-hand
// sides, and the conjugate-gradient solver that takes them.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "constructions/scattered/scattered_sites.hpp"
#include "base/pages.hpp"
#include "interpatch/knot_vector.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::detail::scattered {

/// A net of nu × nv control points over knots on [0, range[0]] × [0, range[1]], index
/// i·nv + j: uniform knots, or, for the coarse nets of a multigrid, a finer net's every
/// other knot (coarser()).
struct Net {
  int p = 3, q = 3, nu = 0, nv = 0;
  KnotVector ku, kv;
  Net(int p_, int q_, int nu_, int nv_, std::array<double, 2> range = {1, 1});
  /// The net on every other knot of `fine` along each direction with more than 4 spans
  /// (the ends kept), the others as they are: its knots are knots of `fine`, so that
  /// the coarse data term is exactly Pᵀ D P of the fine one (restrict_system). From
  /// an even count of spans it is uniform again; from an odd count one span of the
  /// finer net stays alone, the widest nearest the middle (the spans stay within about
  /// a factor 2 of each other on every net below).
  static Net coarser(const Net& fine);
  [[nodiscard]] std::size_t size() const { return static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv); }
  /// ku.find_span(t) and kv.find_span(t).
  [[nodiscard]] int span_u(double t) const { return ku.find_span(t); }
  [[nodiscard]] int span_v(double t) const { return kv.find_span(t); }
  /// ku.basis(span, t, out) and kv.basis(span, t, out): on spans whose knots are all
  /// evenly spaced, the recurrence's denominators are 1, 2 .. p spacings, so no division
  /// is left (a third of a pass over the points); the clamped ends' spans, and every
  /// span of a net whose knots are not even, by the knots.
  void basis_u(int span, double t, double* out) const {
    if (even[0]) return uniform_basis(ku, inv_h[0], span, t, out);
    ku.basis(span, t, out);
  }
  void basis_v(int span, double t, double* out) const {
    if (even[1]) return uniform_basis(kv, inv_h[1], span, t, out);
    kv.basis(span, t, out);
  }
  /// The same knots in both directions.
  [[nodiscard]] bool same_knots(const Net& o) const { return ku.values() == o.ku.values() && kv.values() == o.kv.values(); }

 private:
  Net(KnotVector u, KnotVector v, std::array<bool, 2> even_);
  static void uniform_basis(const KnotVector& k, double inv_h, int span, double t, double* out);
  std::array<double, 2> inv_h{};  // 1 / the knot spacing (on average, when not even)
  std::array<bool, 2> even{true, true};
};

/// A symmetric matrix whose row (i, j) couples only the control points (i + di, j + dj)
/// with |di| ≤ hu, |dj| ≤ hv. Row r keeps the upper half: offsets k = (di, dj) with
/// di > 0, or di = 0 and dj ≥ 0.
class NetMatrix {
 public:
  /// Which part of a packed entry a read takes: the entry (to 2^-39 of its row), or its
  /// float alone, what the multigrid preconditioner works with (pack()). The same for a
  /// matrix not packed.
  enum class Part { whole, floats };
  NetMatrix(int nu, int nv, int hu, int hv);
  [[nodiscard]] int nu() const { return nu_; }
  [[nodiscard]] int nv() const { return nv_; }
  [[nodiscard]] int hu() const { return hu_; }
  [[nodiscard]] int hv() const { return hv_; }
  [[nodiscard]] std::size_t rows() const { return static_cast<std::size_t>(nu_) * static_cast<std::size_t>(nv_); }
  /// Index of offset (di, dj) in a row (di ≥ 0; dj ≥ 0 when di = 0).
  [[nodiscard]] int offset(int di, int dj) const { return di == 0 ? dj : hv_ + 1 + (di - 1) * (2 * hv_ + 1) + dj + hv_; }
  [[nodiscard]] double& at(std::size_t row, int k) {
    make_writable();
    return a_[row * static_cast<std::size_t>(width_) + static_cast<std::size_t>(k)];
  }
  [[nodiscard]] double at(std::size_t row, int k, Part part = Part::whole) const {
    if (mirrored_) return full_[row * full_width() + static_cast<std::size_t>(in_full_[static_cast<std::size_t>(k)])];
    if (packed_) return packed_at(row, k, part);
    return a_[row * static_cast<std::size_t>(width_) + static_cast<std::size_t>(k)];
  }
  /// Row `row`'s upper half in doubles (offset order), when the matrix is in that form
  /// (neither mirrored nor packed); nullptr otherwise.
  [[nodiscard]] const double* upper(std::size_t row) const {
    return mirrored_ || packed_ ? nullptr : a_.data() + row * static_cast<std::size_t>(width_);
  }
  /// Entries a row of the upper half.
  [[nodiscard]] int width() const { return width_; }
  /// Row `row`'s upper half (width() entries, offset order) into `out`, as `part` reads
  /// them: one call a row where at() decodes a packed entry each.
  void upper_row(std::size_t row, double* out, Part part = Part::whole) const;
  /// The upper half in doubles, taken for writing (make_writable()): entry (row, k) at
  /// row · width() + k, for passes that add to many entries at once.
  [[nodiscard]] double* upper_for_writing() {
    make_writable();
    return a_.data();
  }
  /// The entry coupling row (i, j), index `row`, with (i + di, j + dj), either half
  /// (|di| <= hu, |dj| <= hv, both inside the net).
  [[nodiscard]] double entry(std::size_t row, int di, int dj, Part part = Part::whole) const {
    if (di > 0 || (di == 0 && dj >= 0)) return at(row, offset(di, dj), part);
    const auto back = static_cast<std::ptrdiff_t>(-di) * nv_ - dj;
    return at(static_cast<std::size_t>(static_cast<std::ptrdiff_t>(row) - back), offset(-di, -dj), part);
  }
  /// y = A x for `cols` interleaved columns (x[r·cols + c]); bands of net rows shared by
  /// the threads.
  void multiply(std::span<const double> x, std::span<double> y, int cols, Part part = Part::whole) const;
  /// The rows of A x for the control points (i, j) with i0 <= i < i1, into the same rows
  /// of y (no other written), the sums in one order whoever calls.
  void multiply_rows(int i0, int i1, std::span<const double> x, std::span<double> y, int cols, Part part = Part::whole) const;
  /// Net rows a band of multiply() holds: fixed, so that the bits do not depend on the
  /// threads.
  static constexpr int band_rows = 32;
  /// The most entries a row of the upper half holds (reach max_degree both ways).
  static constexpr int max_width = max_degree + 1 + max_degree * (2 * max_degree + 1);
  /// Row (i, j) of A times x, column by column, into acc.
  void row_product(int i, int j, std::span<const double> x, std::size_t cols, double* acc) const;
  /// This matrix set to d + s·f (all three of one net and one pattern).
  void assign_sum(const NetMatrix& d, const NetMatrix& f, double s);
  /// Scales every entry by s.
  void scale(double s);
  /// Keeps every row whole, the lower half mirrored from the upper, so that products
  /// and sweeps read one contiguous row instead of entries spread over the rows above
  /// (about 5 times faster through the general path); the upper half alone is then let
  /// go. Changing an entry goes back to the upper half. Nothing for cubic nets (reach
  /// 3 × 3), whose products read each entry of the upper half once for its row and its
  /// mirror, faster with half the memory.
  void mirror();
  /// Back to the upper half alone, the smaller form (a matrix kept for later); a packed
  /// matrix stays packed.
  void unmirror();
  /// Keeps each entry of a cubic net's matrix (nothing for others) in 6 bytes instead of
  /// 8: the entry rounded to a float, in place (the rest of the pages given back), and
  /// the remainder apart in 16 bits, in steps of 2^-38 of the binade of the row's
  /// largest float: within 2^-39 of the row's largest entry (conjugate gradients stop at
  /// a residual of 1e-12). Products decode it as they read it, or read its floats alone
  /// (Part::floats, contiguous); a 512² net's matrix takes 40 MB instead of 52. Left in
  /// doubles when an entry is beyond 2^100. Changing an entry goes back to doubles
  /// (those decoded).
  void pack();
  [[nodiscard]] bool packed() const { return packed_; }
  /// The form at() writes (the upper half in doubles), taken now: before threads write
  /// through at(), which would otherwise change the form under them.
  void make_writable() {
    if (mirrored_) unmirror();
    if (packed_) unpack();
  }
  /// Bytes a control point takes at most: the upper half, and while mirroring both forms
  /// at once (never for cubic nets, which stay in the upper half).
  static std::size_t bytes_per_row(int hu, int hv) {
    const int upper = hv + 1 + hu * (2 * hv + 1);
    return sizeof(double) * static_cast<std::size_t>(upper + (stays_upper(hu, hv) ? 0 : (2 * hu + 1) * (2 * hv + 1)));
  }

 private:
  // Cubic nets' products read the upper half alone (multiply_rows), a quarter faster
  // than whole rows.
  static bool stays_upper(int hu, int hv) { return hu == 3 && hv == 3; }
  [[nodiscard]] std::size_t full_width() const { return static_cast<std::size_t>((2 * hu_ + 1) * (2 * hv_ + 1)); }
  [[nodiscard]] double packed_at(std::size_t row, int k, Part part) const;
  void unpack();
  void unpack_rows(std::size_t count);  // the first `count` rows of a packed form back to doubles
  int nu_, nv_, hu_, hv_, width_;
  // Zero pages first touched as they are written, in huge pages where the kernel can
  // (ZeroedDoubles). The sweeps read the matrix in strides of a net row: with huge pages,
  // conjugate gradients on a 512² net took a tenth less time. Given back when freed:
  // mappings kept for reuse (large_allocator) held their memory through the tolerance's
  // doubling nets and the folds of "auto", 8 and 27 MB more at the peak.
  using Values = ZeroedDoubles;
  Values a_;  // the upper half, `width_` a row; empty while mirrored
  Values full_;  // (2hu+1)(2hv+1) a row, (di, dj) row-major from (-hu, -hv); empty unless mirrored
  std::vector<int> in_full_;  // upper offset k's place in a whole row
  bool mirrored_ = false;
  bool packed_ = false;  // a_'s bytes hold packed rows' floats, rests_ their rests (pack())
  // A packed matrix's rests, left unset when made (pack() writes each on the threads,
  // its pages first touched there); from the heap and given back when freed.
  template <class T>
  struct Unset : std::allocator<T> {
    template <class U>
    struct rebind {
      using other = Unset<U>;
    };
    Unset() noexcept = default;
    template <class U>
    Unset(const Unset<U>&) noexcept {}
    template <class U>
    void construct(U* p) noexcept {
      ::new (static_cast<void*>(p)) U;
    }
  };
  using Rests = std::vector<std::int16_t, Unset<std::int16_t>>;
  Rests rests_;
};

/// A fit's system: the matrix (the data term, then the fairness term added to it) and
/// the data term's right-hand sides, `cols` of them interleaved.
struct System {
  NetMatrix a;
  std::vector<double> rhs;
  int cols = 1;
};

/// The points a fit takes: unit sites, weights (0: left out; all 1 when empty), and the
/// values fitted (cols per point, interleaved); or, when `points` is given, its points
/// in their order, read from the input on each use.
struct Samples {
  std::span<const std::array<double, 2>> site;  ///< in the net's domain
  std::span<const double> weight;
  std::span<const double> value;
  int cols = 1;
  const FitPoints* points = nullptr;

  [[nodiscard]] std::size_t size() const { return points ? points->size() : site.size(); }
  [[nodiscard]] double weight_at(std::size_t k) const { return weight.empty() ? 1.0 : weight[k]; }
  [[nodiscard]] std::array<double, 2> site_at(std::size_t k) const { return points ? points->unit(k) : site[k]; }
  /// FitPoints::prefetch, when the points are read from the input.
  [[gnu::always_inline]] void prefetch(std::size_t k) const {
    if (points) points->prefetch(k);
  }
  /// Point k's cols values into v.
  void values_at(std::size_t k, double* v) const {
    if (points) return points->value(k, v);
    for (int c = 0; c < cols; ++c) v[c] = value[k * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c)];
  }
};

/// The normal equations of the data term, Σ w_k B(s_k) B(s_k)ᵀ and Σ w_k B(s_k) Q_k,
/// in one pass over the points sorted by knot cell, cells of one colour of a
/// (p+1) × (q+1) pattern in parallel: no two write the same entry, and each entry's
/// sum runs in the same order on any number of threads.
void add_data_term(const Net& net, const Samples& s, System& sys);

/// Adds `s` times the thin-plate term ∫∫ S_uu² + 2 S_uv² + S_vv² of the control net
/// over its domain (second divided differences over the Greville abscissae), or,
/// when `diagonal` is given, only sums its diagonal there (one entry per control point).
void add_fairness(const Net& net, NetMatrix* a, double s, std::vector<double>* diagonal = nullptr);

/// xᵀ F x for the thin-plate term F that add_fairness adds (with s = 1), summed over
/// the `cols` columns of x.
double fairness_energy(const Net& net, std::span<const double> x, int cols);

/// The mean of a matrix's diagonal.
double mean_diagonal(const NetMatrix& m);

/// What a solve reached.
struct Solved {
  int iterations = 0;
  double residual = 0;  ///< the largest over the columns of |r| / |b|
};

/// z ≈ A⁻¹ r for `cols` interleaved columns: a symmetric positive definite operator.
using Preconditioner = std::function<void(std::span<const double> r, std::span<double> z, int cols)>;

/// Whether conjugate gradients should go on, asked after each step with the steps
/// taken and the residual reached (and once before the first).
using KeepGoing = std::function<bool(int iterations, double residual)>;

/// Solves A x = b by conjugate gradients, preconditioned by `precondition` (the
/// diagonal when empty), from the x given, each column to a residual of `rel` of its
/// right-hand side, `max_iter` steps, or until `keep_going` says no. Every sum runs in
/// blocks of fixed size: the same bits on any number of threads. The residual is kept in
/// `residual_room` when it has b's size (b itself when the caller needs b no more: its
/// values are then lost), otherwise in a vector of its own.
Solved solve_cg(const NetMatrix& a, std::span<const double> b, std::span<double> x, int cols, double rel, int max_iter,
                const Preconditioner& precondition = {}, const KeepGoing& keep_going = {}, std::span<double> residual_room = {});

/// A sparse LDLᵀ decomposition of A (Eigen's, fill-reducing ordering), factored once
/// and solved for any number of right-hand sides: exact to rounding whatever the
/// conditioning, for nets small enough that its fill stays cheap.
class DirectSolver {
 public:
  explicit DirectSolver(const NetMatrix& a);
  ~DirectSolver();
  DirectSolver(DirectSolver&&) noexcept;
  DirectSolver& operator=(DirectSolver&&) noexcept;
  /// False when A is not positive definite.
  [[nodiscard]] bool ok() const;
  /// x = A⁻¹ b, `cols` interleaved columns.
  void solve(std::span<const double> b, std::span<double> x, int cols) const;

 private:
  struct Factor;
  std::unique_ptr<Factor> f_;
};

/// Solves A x = b with a DirectSolver. False when A is not positive definite.
bool solve_direct(const NetMatrix& a, std::span<const double> b, std::span<double> x, int cols);

}  // namespace interpatch::detail::scattered
