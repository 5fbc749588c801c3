#pragma once
// The stages of a curve network's surface (network.cpp builds it): the network
// prepared (network_prepare.cpp), its crossings arranged (network_arrange.cpp), the
// curves placed at the common parameters (network_place.cpp), and the finished
// surface checked against the curves given (network_checks.cpp). Family 0 is the
// u-curves, 1 the v-curves.

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "base/text.hpp"
#include "blends/blended_terms.hpp"
#include "constructions/network/network_curves.hpp"
#include "interpatch/network.hpp"

namespace interpatch::detail {

constexpr const char* curves_name(int a) { return a == 0 ? "u_curves" : "v_curves"; }
constexpr const char* params_name(int a) { return a == 0 ? "u_params" : "v_params"; }

/// Indices as a message lists them: "0, 2, 5".
std::string index_list(const std::vector<std::size_t>& v);

// The network as the construction uses it: every curve over [0, 1]; in a closed
// direction a), the curves along it closed and the closing curve of the family across
// it left out; in an open direction, the curves along it open.
struct Prepared {
  std::array<std::vector<BSplineCurve>, 2> along;  // along[0]: the u_curves, along[1]: the v_curves
  std::array<bool, 2> closed{false, false};
  std::array<bool, 2> closing{false, false};  // closing[a]: the last curve across direction a left out
  std::array<std::vector<BSplineCurve>, 2> input;  // the curves as given, over [0, 1]
  std::array<std::vector<bool>, 2> reshaped;       // along[a][j] is not input[a][j] (closed with a C0 seam)
  double tol = 0;       // how far curves may miss each other (NetworkOptions::tolerance)
  double diagonal = 0;  // of the control points' bounding box
  double rounding = 0;  // DataScale::rounding
  double strict = 0;    // 1e-7 of the diagonal, or the rounding floor where that is larger
  // How near curves must be, how near a fit: the tolerance, never below the rounding.
  [[nodiscard]] double fit() const { return std::max(std::min(tol, strict), rounding); }
  std::vector<std::string> notes;
  std::function<std::string(int, std::size_t)> curve_name;
  [[nodiscard]] std::string name(int family, std::size_t index) const {
    return curve_name ? curve_name(family, index) : cat(curves_name(family), "[", index, "]");
  }
};

/// The network prepared: curves over [0, 1], closed where the network is, the closing
/// curves found and left out.
Prepared prepare(const CurveNetwork& n, const NetworkOptions& o);

// What the crossings tell: every pair's closest points, the order of each family,
// the curves that run against theirs, and the common parameters. Indices are those of
// the prepared curves (the given ones, a closing curve left out).
struct Arrangement {
  std::vector<std::vector<Crossing>> X;  // X[j][i]: u-curve j and v-curve i
  std::array<std::vector<std::size_t>, 2> order;  // order[a][k]: the curve of family a at position k
  std::array<std::vector<bool>, 2> reversed, degenerate;
  std::array<std::vector<double>, 2> params;  // params[a][k]: where the surface has the curve at position k
  // to[a][j]: curve j's own parameters at its crossings, by position of the other family
  // (closed: unwrapped, from the seam's on; a curve against its family: decreasing).
  std::array<std::vector<std::vector<double>>, 2> to;
  double keep = 0;  // how close a curve must pass its crossings at the common parameters to be kept
  double snap = 0;  // how near its end a crossing must be to be at its end: min(tolerance, 1e-7 diagonal)
};

/// The crossings of every pair of curves (or the given parameters, where the curves
/// meet there), the families ordered and the common parameters found.
Arrangement arrangement(const Prepared& n, const CurveNetwork& net);

/// Own parameter on curve j of family a where it crosses curve i of the other family.
inline double crossing_param(const Arrangement& r, int a, std::size_t j, std::size_t i) {
  return a == 0 ? r.X[j][i].s : r.X[i][j].t;
}

/// Cardinal functions φ_i(t_k) = δ_ik over the node parameters t; periodic over
/// [0, 1) for a closed direction (t from 0 to below 1).
std::vector<Scalar> cardinals(const std::vector<double>& t, NetworkMethod method, bool closed);

// Which curves of family a are kept as they are and which re-expressed, with their
// maps (over [0, 1] both ways) in the report; the points each will have at the
// common parameters of the other family: node[k][i] for the curve at position k.
struct Plan {
  std::vector<bool> keep;  // by position
  std::vector<std::vector<Vec3>> node;
};

Plan plan(const Prepared& n, const Arrangement& r, int a, std::vector<NetworkCurveReport>& report);

/// The curves of family a in position order, as planned, and how far the surface is
/// from each given curve (in the report).
std::vector<BSplineCurve> place_curves(const Prepared& n, const Arrangement& r, int a, const Plan& mine,
                                       const Plan& other, const std::vector<Scalar>& phi,
                                       std::vector<NetworkCurveReport>& report);

/// Each curve against the finished surface `t`: the reports' distances, and for each
/// curve farther than the strict distance, "name by distance".
std::vector<std::string> check_curves(const CurveNetwork& network, const Prepared& n, const Arrangement& r,
                                      const std::shared_ptr<BlendedTerms>& t, NetworkReport& rep);

/// The closing curves' reports: the seam curve's, moved to the closing curve's domain
/// and direction, with its distance from the finished surface `t` (added to `far`).
void check_closing(const CurveNetwork& network, const Prepared& n, const Arrangement& r,
                   const std::shared_ptr<BlendedTerms>& t, NetworkReport& rep, std::vector<std::string>& far);

/// The notes of the surface: the preparation's, and what was sorted, turned,
/// re-expressed, and how far the surface departs from curves (`far`).
void add_notes(const CurveNetwork& network, Prepared& n, const Arrangement& r, const NetworkReport& rep,
               const std::vector<std::string>& far, BlendedTerms& t);

}  // namespace interpatch::detail
