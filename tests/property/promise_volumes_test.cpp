// The promise harness for the volume families (issue 36): trilinear, coons_volume
// (linear and Hermite blending), hermite_volume, interpolate_volume (closed
// directions too) and the bspline_volume round trip. See promise_harness.hpp for the
// generators and the independent oracle.

#include <gtest/gtest.h>

#include "promise_harness.hpp"

namespace interpatch::promise {
namespace {

constexpr std::size_t kCases = 1000;

std::string at3(double u, double v, double w) {
  return "(" + std::to_string(u) + ", " + std::to_string(v) + ", " + std::to_string(w) + ")";
}

// ------------------------------------------------------------------ trilinear

TEST(PromiseVolumes, Trilinear) {
  Vec3 P[2][2][2];
  run_family(
      "trilinear", 0x7e11, kCases, {errc::missing_field, errc::wrong_type},
      [&](std::mt19937_64& g) {
        const Frame f = random_frame(g);
        const int kind = pick(g, 0, 5);
        const Vec3 base = f.at(Vec3{});
        for (int i = 0; i < 2; ++i)
          for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k) {
              P[i][j][k] = f.at(Vec3{double(i), double(j), double(k)} + local_point(g, 0.3));
              if (kind == 0 && i == 1) P[i][j][k] = base + f.scale * 1e-12 * local_point(g);  // a face collapsed to a point
              if (kind == 1) P[i][j][k] = f.at(local_point(g));                               // folded, tangled
            }
        json spec = {{"type", "trilinear"}};
        for (int i = 0; i < 2; ++i)
          for (int j = 0; j < 2; ++j)
            for (int k = 0; k < 2; ++k) spec[std::string("p") + char('0' + i) + char('0' + j) + char('0' + k)] = to_json(P[i][j][k]);
        return spec;
      },
      [&](const json&, io::Construction& c, Findings& f) {
        Box box;
        for (auto& a : P)
          for (auto& b : a)
            for (auto& q : b) box.add(q);
        const auto t = check_volume_common(c, box, f);
        if (!t) return f.add("trilinear without an exact form");
        // eight corners with weights in [0, 1] summing to 1: rounding, 32 units
        const double tol = rounding(box, 32);
        for (double u : {0.0, 0.3, 1.0})
          for (double v : {0.0, 0.55, 1.0})
            for (double w : {0.0, 0.8, 1.0}) {
              Vec3 want{};
              for (int i = 0; i < 2; ++i)
                for (int j = 0; j < 2; ++j)
                  for (int k = 0; k < 2; ++k)
                    want += ((i ? u : 1 - u) * (j ? v : 1 - v) * (k ? w : 1 - w)) * P[i][j][k];
              f.near("trilinear formula at " + at3(u, v, w), t->eval(u, v, w).s, want, tol);
            }
      },
      0.99);
}

// ------------------------------------------------------------------ coons_volume

TEST(PromiseVolumes, CoonsVolume) {
  Tensor truth;
  std::string blending;
  run_family(
      "coons_volume", 0xc0457, kCases,
      {errc::missing_field, errc::wrong_type, errc::unknown_type, errc::corner_gap, errc::no_exact_form,
       errc::tangent_mismatch, errc::incompatible_twist},
      [&](std::mt19937_64& g) {
        const Frame f = random_frame(g);
        int p[3];
        std::size_t n[3];
        const bool periodic[3] = {false, false, false};
        for (int a = 0; a < 3; ++a) {
          p[a] = pick(g, 1, 2);
          n[a] = static_cast<std::size_t>(p[a] + 1 + pick(g, 0, 1));
        }
        truth = random_tensor(g, f, 3, p, n, periodic, 0.2);
        blending = chance(g, 0.5) ? "linear" : "hermite";
        const char* names[6] = {"u0", "u1", "v0", "v1", "w0", "w1"};
        json faces = json::object();
        for (int a = 0; a < 3; ++a)
          for (int e = 0; e < 2; ++e) {
            const Tensor face = contract(truth, a, double(e));
            json spec = surface_spec(face);
            // a face of degree (1, 1) on 2 × 2 control points is bilinear: give it so now and then
            if (face.p[0] == 1 && face.p[1] == 1 && face.n[0] == 2 && face.n[1] == 2 && chance(g, 0.5))
              spec = {{"type", "bilinear"}, {"p00", to_json(face.cp[0])}, {"p01", to_json(face.cp[1])},
                      {"p10", to_json(face.cp[2])}, {"p11", to_json(face.cp[3])}};
            faces[names[2 * a + e]] = spec;
          }
        json spec = {{"type", "coons_volume"}, {"faces", faces}};
        if (blending == "hermite" || chance(g, 0.5)) spec["blending"] = blending;
        return spec;
      },
      [&](const json&, io::Construction& c, Findings& f) {
        const Box box = box_of(truth);
        const auto t = check_volume_common(c, box, f);
        if (!t) return f.add("coons_volume of polynomial faces without an exact form");
        // the faces: the truth's own faces, so the truth's own de Boor there; data_tol
        // as for surfaces (sums of B-splines of the same numbers)
        const double tol = data_tol(box);
        for (double x : {0.0, 0.4, 1.0})
          for (double y : {0.0, 0.7, 1.0})
            for (double e : {0.0, 1.0}) {
              f.near("face u=" + std::to_string(e) + " at " + at3(e, x, y), t->eval(e, x, y).s, truth.eval(e, x, y).s, tol);
              f.near("face v=" + std::to_string(e) + " at " + at3(x, e, y), t->eval(x, e, y).s, truth.eval(x, e, y).s, tol);
              f.near("face w=" + std::to_string(e) + " at " + at3(x, y, e), t->eval(x, y, e).s, truth.eval(x, y, e).s, tol);
            }
        // The Boolean sum S = U + V + W − UV − VW − UW + UVW of the truth's faces,
        // edges and corners, blended by f: 26 terms of blends below 1, so 8 × data_tol.
        auto bl = [&](double x) { return blending == "linear" ? x : x * x * (3 - 2 * x); };
        auto T = [&](double u, double v, double w) { return truth.eval(u, v, w).s; };
        for (double u : {0.2, 0.6})
          for (double v : {0.35, 0.9})
            for (double w : {0.1, 0.5}) {
              const double a[2] = {1 - bl(u), bl(u)}, b[2] = {1 - bl(v), bl(v)}, d[2] = {1 - bl(w), bl(w)};
              Vec3 S{};
              for (int i = 0; i < 2; ++i) {
                S += a[i] * T(i, v, w) + b[i] * T(u, i, w) + d[i] * T(u, v, i);
                for (int j = 0; j < 2; ++j) {
                  S -= (a[i] * b[j]) * T(i, j, w) + (b[i] * d[j]) * T(u, i, j) + (a[i] * d[j]) * T(i, v, j);
                  for (int k = 0; k < 2; ++k) S += (a[i] * b[j] * d[k]) * T(i, j, k);
                }
              }
              f.near(blending + " Coons volume formula at " + at3(u, v, w), t->eval(u, v, w).s, S, 8 * tol);
            }
      });
}

// ------------------------------------------------------------------ hermite_volume

TEST(PromiseVolumes, HermiteVolume) {
  run_family(
      "hermite_volume", 0x4e2701, kCases, {errc::missing_field, errc::wrong_type, errc::size_mismatch},
      [](std::mt19937_64& g) {
        const Frame f = random_frame(g);
        json corners = json::array();
        for (int n = 0; n < 8; ++n) {
          json c = {{"p", to_json(f.at(Vec3{double(n >> 2), double((n >> 1) & 1), double(n & 1)} + local_point(g, 0.3)))}};
          for (const char* d : {"du", "dv", "dw"}) c[d] = to_json(f.scale * local_point(g, 2));
          for (const char* d : {"duv", "duw", "dvw", "duvw"})
            if (chance(g, 0.5)) c[d] = to_json(f.scale * local_point(g, 2));
          corners.push_back(c);
        }
        return json{{"type", "hermite_volume"}, {"corners", corners}};
      },
      [](const json& spec, io::Construction& c, Findings& f) {
        const char* names[8] = {"p", "dw", "dv", "dvw", "du", "duw", "duv", "duvw"};  // index 4a + 2b + c
        Vec3 D[8][8];  // D[corner][which derivative]
        Box box;
        double dsize = 0;
        for (int n = 0; n < 8; ++n)
          for (int m = 0; m < 8; ++m) {
            const json& k = spec["corners"][n];
            D[n][m] = k.contains(names[m]) ? from_json(k[names[m]]) : Vec3{};
            if (m == 0)
              box.add(D[n][m]);
            else
              dsize = std::max(dsize, norm(D[n][m]));
          }
        // the derivatives pull the volume out of the corners' box by up to |D| / 4 per term
        Box grown = box;
        grown.add(box.lo - 2 * Vec3{dsize, dsize, dsize});
        grown.add(box.hi + 2 * Vec3{dsize, dsize, dsize});
        const auto t = check_volume_common(c, grown, f);
        if (!t) return f.add("hermite_volume without an exact form");
        auto I = [](int i, int a, double x) {
          if (a == 0) return i == 0 ? 1 - 3 * x * x + 2 * x * x * x : 3 * x * x - 2 * x * x * x;
          return i == 0 ? x - 2 * x * x + x * x * x : -x * x + x * x * x;
        };
        // 64 terms of Hermite functions below 1: rounding of the data's size, 256 units
        const double tol = 256 * eps * (box.magnitude() + dsize);
        for (double u : {0.0, 0.4, 1.0})
          for (double v : {0.15, 0.5, 1.0})
            for (double w : {0.0, 0.7}) {
              Vec3 want{};
              for (int n = 0; n < 8; ++n)
                for (int m = 0; m < 8; ++m)
                  want += (I(n >> 2, m >> 2, u) * I((n >> 1) & 1, (m >> 1) & 1, v) * I(n & 1, m & 1, w)) * D[n][m];
              f.near("tricubic Hermite formula at " + at3(u, v, w), t->eval(u, v, w).s, want, tol);
            }
        for (int n = 0; n < 8; ++n) {
          const Jet J = t->eval(n >> 2, (n >> 1) & 1, n & 1);
          f.near("S_u at corner " + std::to_string(n), J.d[0], D[n][4], 4 * tol);
          f.near("S_v at corner " + std::to_string(n), J.d[1], D[n][2], 4 * tol);
          f.near("S_w at corner " + std::to_string(n), J.d[2], D[n][1], 4 * tol);
        }
      },
      0.99);
}

// ------------------------------------------------------------------ interpolate_volume

TEST(PromiseVolumes, InterpolateVolume) {
  std::vector<Vec3> grid;  // distinct points, C order
  std::size_t n[3];
  bool closed[3];
  std::string param;
  run_family(
      "interpolate_volume", 0x1a7e3, kCases,
      {errc::too_few_points, errc::zero_chord, errc::closing_gap, errc::invalid_degree, errc::singular,
       errc::wrong_type, errc::size_mismatch},
      [&](std::mt19937_64& g) {
        const Frame f = random_frame(g);
        int deg[3];
        bool repeat[3];
        for (int a = 0; a < 3; ++a) {
          closed[a] = chance(g, 0.15);
          n[a] = static_cast<std::size_t>(pick(g, closed[a] ? 3 : 2, 4));
          deg[a] = chance(g, 0.5) ? std::min<int>(3, int(n[a]) - 1) : pick(g, 1, int(n[a]) - 1);
          repeat[a] = closed[a] && chance(g, 0.5);
        }
        param = std::vector<std::string>{"uniform", "chord", "centripetal"}[static_cast<std::size_t>(pick(g, 0, 2))];
        const int p1[3] = {1, 1, 1};
        const Tensor shape = random_tensor(g, f, 3, p1, n, closed, 0.02);
        grid.resize(shape.cp.size());
        for (std::size_t i = 0; i < grid.size(); ++i) grid[i] = shape.cp[i] + f.scale * local_point(g, 0.08);
        json pts = json::array();
        for (std::size_t i = 0; i < n[0] + repeat[0]; ++i) {
          json a = json::array();
          for (std::size_t j = 0; j < n[1] + repeat[1]; ++j) {
            json b = json::array();
            for (std::size_t k = 0; k < n[2] + repeat[2]; ++k)
              b.push_back(to_json(grid[((i % n[0]) * n[1] + j % n[1]) * n[2] + k % n[2]]));
            a.push_back(b);
          }
          pts.push_back(a);
        }
        json spec = {{"type", "interpolate_volume"}, {"points", pts}, {"param", param}};
        if (closed[0] || closed[1] || closed[2] || chance(g, 0.2)) spec["periodic"] = {closed[0], closed[1], closed[2]};
        if (chance(g, 0.7)) spec["degree"] = {deg[0], deg[1], deg[2]};
        return spec;
      },
      [&](const json&, io::Construction& c, Findings& f) {
        Box box;
        for (const Vec3& q : grid) box.add(q);
        const auto t = check_volume_common(c, box, f);
        if (!t) return f.add("interpolate_volume without an exact form");
        std::vector<double> par[3];
        for (int a = 0; a < 3; ++a) {
          if (t->periodic[a] != closed[a]) f.add("exact form periodic flag differs from the spec");
          std::vector<std::vector<Vec3>> lines;
          const int b = (a + 1) % 3, d = (a + 2) % 3;
          for (std::size_t x = 0; x < n[b]; ++x)
            for (std::size_t y = 0; y < n[d]; ++y) {
              std::vector<Vec3> line;
              for (std::size_t s = 0; s < n[a]; ++s) {
                std::size_t idx[3];
                idx[a] = s;
                idx[b] = x;
                idx[d] = y;
                line.push_back(grid[(idx[0] * n[1] + idx[1]) * n[2] + idx[2]]);
              }
              lines.push_back(line);
            }
          par[a] = own_grid_params(lines, param, closed[a]);
        }
        for (std::size_t i = 0; i < n[0]; ++i)
          for (std::size_t j = 0; j < n[1]; ++j)
            for (std::size_t k = 0; k < n[2]; ++k)
              f.near("data point [" + std::to_string(i) + "][" + std::to_string(j) + "][" + std::to_string(k) + "]",
                     t->eval(par[0][i], par[1][j], par[2][k]).s, grid[(i * n[1] + j) * n[2] + k], data_tol(box));
      },
      0.8);
}

// ------------------------------------------------------------------ bspline_volume round trip

TEST(PromiseVolumes, BSplineVolumeRoundTrip) {
  Tensor given;
  run_family(
      "bspline_volume", 0xb57, kCases,
      {errc::missing_field, errc::wrong_type, errc::invalid_degree, errc::non_increasing, errc::invalid_knots,
       errc::size_mismatch, errc::invalid_weight},
      [&](std::mt19937_64& g) {
        const Frame f = random_frame(g);
        int p[3];
        std::size_t n[3];
        bool periodic[3];
        for (int a = 0; a < 3; ++a) {
          periodic[a] = chance(g, 0.15);
          p[a] = pick(g, 1, chance(g, 0.1) ? 5 : 3);
          n[a] = static_cast<std::size_t>(p[a] + 1 + pick(g, 0, 2));
        }
        given = random_tensor(g, f, 3, p, n, periodic, 0.2);
        if (chance(g, 0.3))
          for (std::size_t i = 0; i < given.cp.size(); ++i) given.w.push_back(std::pow(10.0, uni(g, -1.5, 1.5)));
        for (int a = 0; a < 3; ++a) {
          const double lo = uni(g, -100, 100), len = std::pow(10.0, uni(g, -2, 2));
          for (double& k : given.knots[a]) k = lo + k * len;
        }
        return volume_spec(given);
      },
      [&](const json&, io::Construction& c, Findings& f) {
        const Box box = box_of(given);
        const auto t = check_volume_common(c, box, f);
        if (!t) return f.add("bspline_volume without an exact form");
        // as for bspline_surface: rounding of the control points' size, times the
        // weights' spread (up to 1e3) when rational, plus the mapping's rounding
        const double tol = rounding(box, given.w.empty() ? 64 : 64e3) + 1e-12 * box.diagonal();
        const auto [u0, u1] = given.domain(0);
        const auto [v0, v1] = given.domain(1);
        const auto [w0, w1] = given.domain(2);
        // and the knots' mapping onto [0, 1], as for bspline_surface
        const double d[3] = {4 * eps * (std::abs(u0) + std::abs(u1)) / (u1 - u0),
                             4 * eps * (std::abs(v0) + std::abs(v1)) / (v1 - v0),
                             4 * eps * (std::abs(w0) + std::abs(w1)) / (w1 - w0)};
        for (double u : {0.0, 0.45, 1.0})
          for (double v : {0.0, 0.21, 0.83})
            for (double w : {0.33, 1.0}) {
              const Jet J = t->eval(u, v, w);
              f.near("exact form vs the spec's own B-spline at " + at3(u, v, w), J.s,
                     given.eval(u0 + u * (u1 - u0), v0 + v * (v1 - v0), w0 + w * (w1 - w0)).s,
                     tol + 2 * (d[0] * norm(J.d[0]) + d[1] * norm(J.d[1]) + d[2] * norm(J.d[2])));
            }
      },
      0.99);
}

}  // namespace
}  // namespace interpatch::promise
