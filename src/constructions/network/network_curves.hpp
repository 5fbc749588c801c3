#pragma once
// The curve work of a network as drawn (network_build.hpp): where two curves cross
// (network_samples.cpp, network_crossings.cpp), the maps from the surface's parameter
// to a curve's (network_map.cpp), and a curve re-expressed so that it passes its
// crossings at given parameters (network_refit.cpp, network_fit.cpp).
// Every curve here is over [0, 1].

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "interpatch/bspline_curve.hpp"
#include "interpatch/error.hpp"
#include "interpatch/network.hpp"

namespace interpatch::detail {

/// t moved by whole periods into [0, 1).
inline double wrap_unit(double t) {
  const double r = t - std::floor(t);
  return r < 1.0 ? r : 0.0;  // a tiny negative t rounds to 1
}

/// A curve's parameter for the surface's: in a closed direction a value just past an
/// end (rounding in the map, or an open curve whose ends meet) is taken around the
/// curve, not refused as outside [0, 1]; in an open one it is held at the end.
inline double on_curve(double x, bool closed) {
  if (!closed) return std::clamp(x, 0.0, 1.0);
  return x >= 0.0 && x <= 1.0 ? x : wrap_unit(x);
}

/// The closest points of two curves: U(s) and V(t), `gap` apart.
struct Crossing {
  double s = 0, t = 0;
  Vec3 a, b;
  double gap = std::numeric_limits<double>::infinity();
};

/// Samples of a curve for the thorough search, made on first use.
class CurveSamples {
 public:
  explicit CurveSamples(const BSplineCurve& c) : c_(&c) {}
  struct Chunk {
    std::size_t first, last;  // samples [first, last]
    Vec3 lo, hi;              // their bounding box
  };
  const std::vector<Vec3>& points() const;
  const std::vector<double>& params() const;
  const std::vector<Chunk>& chunks() const;

 private:
  void make() const;
  const BSplineCurve* c_;
  mutable std::vector<Vec3> p_;
  mutable std::vector<double> t_;
  mutable std::vector<Chunk> chunks_;
};

/// Where U and V come closest: a coarse pass over 65 × 65 parameter pairs and
/// Gauss–Newton on U(s) − V(t); when that ends farther apart than `tol`, a thorough
/// pass over 8 samples of every knot span of each curve (boxes of 32 samples pruned
/// by their distance) and Gauss–Newton from the closest pair found. A closed curve's
/// parameter wraps around its seam; an open one's stays in [0, 1].
Crossing closest_points(const BSplineCurve& U, const BSplineCurve& V, bool closed_u, bool closed_v, double tol,
                        const CurveSamples& su, const CurveSamples& sv);

/// Every place where U and V meet within `tol`: Gauss–Newton from each pair of
/// samples (8 per knot span) nearer than any pair around it, and within a sample
/// step of each other; nearest first. Two places are one where the curves stay
/// within `tol` of each other between them (a shallow or tangential crossing).
std::vector<Crossing> crossings(const BSplineCurve& U, const BSplineCurve& V, bool closed_u, bool closed_v, double tol,
                                const CurveSamples& su, const CurveSamples& sv);

/// The monotone map through (at[i], to[i]) (at increasing, to strictly monotone):
/// slopes of the C2 cubic spline (natural ends, or periodic when `closed`: to[last]
/// is then to[0] ± 1 at at[last] = 1), or of Fritsch–Butland where that spline is
/// not monotone. Two points: the straight line.
Reparametrization monotone_map(std::vector<double> at, std::vector<double> to, bool closed);

/// u with map(u) = y, for y between map(0) and map(1) (closed: unwrapped).
double inverse(const Reparametrization& map, double y);

/// Thrown by refit() when a curve cannot be re-expressed within the target: which
/// job, the message saying how far it stays. The network names the curve.
class RefitShortfall : public error {
 public:
  RefitShortfall(std::size_t job, const std::string& message) : error(errc::tolerance_not_met, message), job_(job) {}
  [[nodiscard]] std::size_t job() const noexcept { return job_; }

 private:
  std::size_t job_;
};

/// One curve to re-express: C (the prepared curve), the curve as given (both over
/// [0, 1]; null when C is it, up to rounding), the correction G the surface adds along the curve's line (see
/// place_curves: S = D + G there; null for none: a loft's sections), and the map.
struct FitJob {
  const BSplineCurve* c;
  const BSplineCurve* given;
  const BSplineCurve* G;
  Reparametrization map;
};

/// Curves of one family re-expressed over the surface's parameter: D_j(u) ≈
/// C_j(map_j(u)), of C_j's degree, through C_j(map_j(nodes[k])) at nodes[k] exactly
/// (to rounding), within `target` of C_j(map_j(u)) measured at 4 points of every span.
/// First on shared knots: every curve's corners (multiple knots) pulled back through
/// its map, and its simple knots pulled back and averaged over the family quantile by
/// quantile (so the exact form of the surface has about as many control points as the
/// densest curve, not the sum of all), spans where some curve is too far halved. When
/// the halvings that would take outnumber all curves' own knots together (curves whose
/// parameters are irregular, e.g. centripetal through uneven stations, break where the
/// average does not), the family shares all its curves' own knots, halved where still
/// too far, if fitting on them is little work; otherwise each curve is fitted on its
/// own knots pulled back, and its spans still too far are cut where the error says, at
/// knots of the other curves or else at coarse dyadic fractions (the exact form merges
/// the family's knots). Rational curves are fitted in homogeneous coordinates.
/// `closed`: every C_j periodic, every D_j periodic over [0, 1).
struct Refit {
  BSplineCurve curve;
  double error = 0;     ///< the largest |D(u) − C(map(u))| measured
  double distance = 0;  ///< the largest |D(u) + G(u) − given(map(u))| at the same points
};
std::vector<Refit> refit(const std::vector<FitJob>& jobs, const std::vector<double>& nodes, bool closed, double target);

/// Where refit starts: the family's shared interior knots (every curve's corners, its
/// simple knots averaged quantile by quantile), each curve's own knots pulled back
/// (with the seam of a closed one), and how many those are together.
struct FamilyKnots {
  std::vector<double> interior;
  std::vector<std::vector<double>> own;
  std::size_t all = 0;
};
FamilyKnots family_knots(const std::vector<FitJob>& jobs, const std::vector<double>& nodes, bool closed);

/// The work of checking a fit, per span, in multiply-adds: 4 points, each 3 curve
/// points of about 30 (a cubic's basis functions and their sum); for parallel_min_work.
inline constexpr std::size_t span_work = 4 * 3 * 30;

/// Curves of one family (`members` of `jobs`) fitted on one knot vector, starting from
/// `interior`, until every one is within `target` of its curve (see refit). Shared
/// knots (`others` null): every span where some curve is farther halved; empty when
/// `all` (the count of the curves' own knots together) is not 0 and the halvings the
/// error calls for would make more knots than that, so the caller takes the curves'
/// own knots instead. One curve on its own knots (`others`: the family's own knots,
/// all curves'): a span farther than half the target by a factor f is cut into about
/// f^(1/4) pieces (the distance falls with the fourth power of the span, the curve C2
/// between its own knots; aiming at half, the cut spans' neighbours, which the new
/// fit moves a little, rarely need another round), at knots of the other curves or
/// else at coarse dyadic fractions.
/// @throws RefitShortfall when the knots grow too many or 60 rounds do not do.
std::optional<std::vector<Refit>> fit_group(const std::vector<FitJob>& jobs, const std::vector<std::size_t>& members,
                                            std::vector<double> interior, const std::vector<double>& nodes,
                                            bool closed, double target, std::size_t all,
                                            const std::vector<double>* others);

/// Parameters in [0, 1] at which a curve of the network is checked against the
/// surface: 4 in every span of its knots (closed: of its period), and the ends.
std::vector<double> check_params(const KnotVector& k);

/// The curve's points at every t of ts, as c.point(t) gives them: for a polynomial
/// curve and increasing ts the span is walked to rather than searched for.
/// @throws error out_of_domain.
std::vector<Vec3> points_at(const BSplineCurve& c, std::span<const double> ts);

}  // namespace interpatch::detail
