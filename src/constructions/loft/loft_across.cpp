// What a loft of curves and a loft of surfaces share: the places of the sections
// across, and the interpolation across them of many values at once.
#include <algorithm>
#include <cmath>

#include "base/text.hpp"
#include "constructions/interpolate/interpolate_internal.hpp"
#include "constructions/loft/loft_across.hpp"

namespace interpatch::detail {

std::vector<double> across_params(std::size_t n, std::size_t lines, const std::function<Vec3(std::size_t, std::size_t)>& point,
                                  Parametrization param, bool periodic, double largest,
                                  const std::function<std::string(std::size_t)>& name) {
  const double root = root_scale(scale_exponent(largest));
  const std::size_t chords = periodic ? n : n - 1;
  std::vector<double> v(n, 0.0);
  if (param == Parametrization::uniform) {
    for (std::size_t k = 0; k < n; ++k) v[k] = static_cast<double>(k) / static_cast<double>(chords);
    return v;
  }
  std::vector<double> sum(n, 0.0), d(chords);
  std::size_t used = 0;
  std::vector<bool> moves(chords, false);  // some line has a non-zero chord there
  for (std::size_t i = 0; i < lines; ++i) {
    double total = 0;
    for (std::size_t k = 0; k < chords; ++k) {
      const double c = distance(point(k, i), point((k + 1) % n, i));
      d[k] = param == Parametrization::centripetal ? std::sqrt(c * root) : c;
      total += d[k];
    }
    if (!(total > 0)) continue;
    ++used;
    double run = 0;
    for (std::size_t k = 0; k < chords; ++k) {
      if (d[k] > 0) moves[k] = true;
      run += d[k];
      if (k + 1 < n) sum[k + 1] += run / total;
    }
  }
  for (std::size_t k = 0; k < chords; ++k)
    if (!moves[k])
      fail(errc::zero_chord, name((k + 1) % n), " lies on ", name(k),
           " everywhere: two sections at one place give the loft no room between them");
  for (std::size_t k = 1; k < n; ++k) v[k] = sum[k] / static_cast<double>(used);
  return v;
}

void check_given_params(const std::vector<double>& v, std::size_t n, bool periodic,
                        const std::function<std::string(std::size_t)>& at, const char* whole) {
  if (v.size() != n) fail(errc::size_mismatch, whole, ": ", n, " sections need ", n, " parameters, got ", v.size());
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(v[k])) fail(errc::not_finite, at(k), " is ", v[k]);
    if (k > 0 && !(v[k] > v[k - 1]))
      fail(errc::non_increasing, at(k), " = ", v[k], " is not greater than ", at(k - 1), " = ", v[k - 1]);
  }
  if (periodic ? (v.front() != 0.0 || !(v.back() < 1.0)) : (v.front() != 0.0 || v.back() != 1.0))
    fail(errc::out_of_domain, whole, " must run from 0 to ",
         periodic ? "below 1 (1 is the first section again)" : "1", ", got ", v.front(), " to ", v.back());
}

namespace {

// The knots across for open lofts: by averaging (The NURBS Book eq. 9.8) over the
// sites, each site with a derivative counted twice, so that every span holds a
// condition (Schoenberg–Whitney) and the spline is C^(q−1) with simple knots.
KnotVector open_knots(const std::vector<double>& v, const std::vector<bool>& derivative, int q) {
  const bool inner = std::any_of(derivative.begin() + 1, derivative.end() - 1, [](bool b) { return b; });
  if (!inner) return averaged_knots(v, q, derivative.front(), derivative.back());
  std::vector<double> sites;
  for (std::size_t k = 0; k < v.size(); ++k) sites.insert(sites.end(), derivative[k] ? 2 : 1, v[k]);
  const std::size_t m = sites.size(), qz = static_cast<std::size_t>(q);
  std::vector<double> k(qz + 1, v.front());
  for (std::size_t j = 1; j + qz < m; ++j) {
    double a = 0;
    for (std::size_t i = j; i < j + qz; ++i) a += sites[i];
    k.push_back(a / static_cast<double>(q));
  }
  k.insert(k.end(), qz + 1, v.back());
  return KnotVector(q, std::move(k));
}

}  // namespace

std::vector<double> span_samples(const KnotVector& k) {
  std::vector<double> b{0.0};
  for (const auto& [x, mult] : k.interior_breaks())
    if (x > 0.0 && x < 1.0) b.push_back(x);
  b.push_back(1.0);
  std::vector<double> t;
  for (std::size_t i = 0; i + 1 < b.size(); ++i)
    for (int j = 0; j < 4; ++j) t.push_back(b[i] + (b[i + 1] - b[i]) * j / 4.0);
  t.push_back(1.0);
  return t;
}

KnotVector interpolate_across(std::vector<double>& rows, std::size_t width, const std::vector<double>& v,
                              const std::vector<bool>& derivative, const std::vector<Condition>& conds, int q,
                              bool periodic) {
  KnotVector kv = KnotVector::bezier(1);
  if (periodic) {
    kv = periodic_knots(v, q);
    factor_periodic_collocation(kv, v).solve(rows.data(), width, width);
    if (q % 2 == 0) {  // the domain starts at a midpoint: start it at the first section
      SeamInsertion seam = seam_insertion(kv, v.front());
      std::vector<double> moved(seam.rows.size() * width);
      for (std::size_t j = 0; j < seam.rows.size(); ++j) {
        const auto& r = seam.rows[j];
        for (std::size_t a = 0; a < width; ++a)
          moved[j * width + a] = r.alpha * rows[r.x * width + a] + (1.0 - r.alpha) * rows[r.y * width + a];
      }
      rows = std::move(moved);
      kv = std::move(seam.knots);
    }
  } else {
    kv = open_knots(v, derivative, q);
    factor_collocation(kv, conds).solve(rows.data(), width, width);
  }
  return kv;
}

}  // namespace interpatch::detail
