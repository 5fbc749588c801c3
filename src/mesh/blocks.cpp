#include "mesh/blocks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

#include "base/text.hpp"

namespace interpatch::mesh {

using detail::fail;

namespace {

// A face of a block seen as a grid of (s, t) nodes.
struct FaceView {
  const PointGrid3* g;
  std::size_t d, a, b;  // the normal direction, then those of s and t
  std::size_t fixed;    // the nodes' index along d
  std::size_t ns() const { return g->extent(a); }
  std::size_t nt() const { return g->extent(b); }
  std::array<std::size_t, 3> index(std::size_t s, std::size_t t) const {
    std::array<std::size_t, 3> x{};
    x[d] = fixed;
    x[a] = s;
    x[b] = t;
    return x;
  }
  const Vec3& at(std::size_t s, std::size_t t) const {
    const auto x = index(s, t);
    return (*g)(x[0], x[1], x[2]);
  }
  // Corner (cs, ct), each 0 or 1.
  const Vec3& corner(std::size_t cs, std::size_t ct) const { return at(cs * (ns() - 1), ct * (nt() - 1)); }
};

FaceView view(const PointGrid3& g, int face) {
  const auto d = static_cast<std::size_t>(face / 2);
  return {&g, d, d == 0 ? 1u : 0u, d == 2 ? 1u : 2u, face % 2 ? g.extent(d) - 1 : 0};
}

std::array<std::size_t, 2> apply(const FaceMap& m, std::size_t s, std::size_t t, std::size_t ns, std::size_t nt) {
  const std::size_t x = m.transpose ? t : s, y = m.transpose ? s : t;
  return {m.flip_s ? ns - 1 - x : x, m.flip_t ? nt - 1 - y : y};
}

constexpr std::array<FaceMap, 8> all_maps = {{{false, false, false}, {false, true, false}, {false, false, true},
                                              {false, true, true}, {true, false, false}, {true, true, false},
                                              {true, false, true}, {true, true, true}}};

// The largest distance between the corners the map pairs.
double corner_distance(const FaceView& p, const FaceView& q, const FaceMap& m) {
  double worst = 0;
  for (std::size_t cs = 0; cs < 2; ++cs)
    for (std::size_t ct = 0; ct < 2; ++ct) {
      const auto c = apply(m, cs, ct, 2, 2);
      worst = std::max(worst, norm(p.corner(cs, ct) - q.corner(c[0], c[1])));
    }
  return worst;
}

bool counts_fit(const FaceView& p, const FaceView& q, const FaceMap& m) {
  return m.transpose ? p.ns() == q.nt() && p.nt() == q.ns() : p.ns() == q.ns() && p.nt() == q.nt();
}

// The largest distance between the nodes the map pairs, and where (p's s, t).
struct Gap {
  double distance = 0;
  std::size_t s = 0, t = 0;
};
Gap node_gap(const FaceView& p, const FaceView& q, const FaceMap& m) {
  Gap g;
  for (std::size_t s = 0; s < p.ns(); ++s)
    for (std::size_t t = 0; t < p.nt(); ++t) {
      const auto o = apply(m, s, t, q.ns(), q.nt());
      const double d = norm(p.at(s, t) - q.at(o[0], o[1]));
      if (d > g.distance) g = {d, s, t};
    }
  return g;
}

double shortest_side(const FaceView& p) {
  return std::min({norm(p.corner(1, 0) - p.corner(0, 0)), norm(p.corner(1, 1) - p.corner(1, 0)),
                   norm(p.corner(0, 1) - p.corner(1, 1)), norm(p.corner(0, 0) - p.corner(0, 1))});
}

bool collapsed(const FaceView& p, double tolerance) {
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = i + 1; j < 4; ++j)
      if (norm(p.corner(i & 1, i >> 1) - p.corner(j & 1, j >> 1)) > tolerance) return false;
  return true;
}

std::string face_text(std::size_t block, int face) {
  return detail::cat("block ", block, " face ", block_face_names[static_cast<std::size_t>(face)]);
}

std::string nodes_text(const FaceView& p) { return detail::cat(p.ns(), " x ", p.nt(), " nodes"); }

// The pair's shared face, if the faces coincide; throws where they nearly do.
std::optional<SharedFace> match(std::span<const PointGrid3> blocks, std::size_t i, int fi, std::size_t j, int fj,
                                double tolerance) {
  const FaceView p = view(blocks[i], fi), q = view(blocks[j], fj);
  double best = std::numeric_limits<double>::infinity();
  std::optional<SharedFace> found;
  bool corners_meet = false;
  Gap nearest;  // the compatible map whose nodes come closest, for the message
  nearest.distance = std::numeric_limits<double>::infinity();
  for (const FaceMap& m : all_maps) {
    const double c = corner_distance(p, q, m);
    best = std::min(best, c);
    if (c > tolerance) continue;
    corners_meet = true;
    if (!counts_fit(p, q, m)) continue;
    const Gap g = node_gap(p, q, m);
    if (g.distance <= tolerance && (!found || g.distance < found->gap)) found = SharedFace{{i, j}, {fi, fj}, m, g.distance};
    if (g.distance < nearest.distance) nearest = g;
  }
  if (found) return found;
  if (corners_meet) {
    const bool any_fit = std::any_of(all_maps.begin(), all_maps.end(), [&](const FaceMap& m) {
      return corner_distance(p, q, m) <= tolerance && counts_fit(p, q, m);
    });
    if (!any_fit)
      fail(errc::block_mismatch, face_text(i, fi), " (", nodes_text(p), ") and ", face_text(j, fj), " (", nodes_text(q),
           ") meet at their corners but their node counts differ; give the directions they share the same count");
    const auto x = p.index(nearest.s, nearest.t);
    fail(errc::block_mismatch, face_text(i, fi), " and ", face_text(j, fj),
         " meet at their corners but not along the face: at node (", x[0], ", ", x[1], ", ", x[2], ") of block ", i,
         " they are ", nearest.distance, " apart (tolerance ", tolerance,
         "); a shared face must coincide node for node");
  }
  if (best < 0.05 * std::min(shortest_side(p), shortest_side(q)))
    fail(errc::block_mismatch, face_text(i, fi), " and ", face_text(j, fj), " nearly meet: their corners are up to ",
         best, " apart (tolerance ", tolerance, "); move them together, or apart");
  return std::nullopt;
}

}  // namespace

std::vector<SharedFace> shared_faces(std::span<const PointGrid3> blocks, double tolerance) {
  std::vector<SharedFace> shared;
  std::vector<std::array<int, 6>> partner(blocks.size());  // index into shared, or -1
  for (auto& p : partner) p.fill(-1);
  for (std::size_t i = 0; i < blocks.size(); ++i)
    for (int fi = 0; fi < 6; ++fi) {
      if (collapsed(view(blocks[i], fi), tolerance)) continue;
      for (std::size_t j = i; j < blocks.size(); ++j)
        for (int fj = j == i ? fi + 1 : 0; fj < 6; ++fj) {
          if (collapsed(view(blocks[j], fj), tolerance)) continue;
          const std::optional<SharedFace> s = match(blocks, i, fi, j, fj, tolerance);
          if (!s) continue;
          for (const auto& [b, f] : {std::pair{i, fi}, std::pair{j, fj}}) {
            const int other = partner[b][static_cast<std::size_t>(f)];
            if (other >= 0) {
              const SharedFace& o = shared[static_cast<std::size_t>(other)];
              const bool first = o.block[0] == b && o.face[0] == f;
              fail(errc::block_mismatch, face_text(b, f), " meets both ",
                   face_text(o.block[first ? 1 : 0], o.face[first ? 1 : 0]), " and ",
                   b == i && f == fi ? face_text(j, fj) : face_text(i, fi), "; a face is shared by two blocks at most");
            }
          }
          partner[i][static_cast<std::size_t>(fi)] = partner[j][static_cast<std::size_t>(fj)] =
              static_cast<int>(shared.size());
          shared.push_back(*s);
        }
    }
  return shared;
}

namespace {

// Union-find whose root is the smallest member: merged nodes sit where the first
// block put them.
struct Sets {
  std::vector<std::size_t> parent;
  explicit Sets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), std::size_t{0}); }
  std::size_t find(std::size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(std::size_t x, std::size_t y) {
    x = find(x);
    y = find(y);
    if (x != y) parent[std::max(x, y)] = std::min(x, y);
  }
};

// Whether the block's directions run left-handed: the sign of its cells' summed
// det J at their first corners.
bool left_handed(const PointGrid3& g) {
  const auto n = g.shape();
  double sum = 0;
  for (std::size_t i = 0; i + 1 < n[0]; ++i)
    for (std::size_t j = 0; j + 1 < n[1]; ++j)
      for (std::size_t k = 0; k + 1 < n[2]; ++k) {
        const Vec3& o = g(i, j, k);
        sum += dot(cross(g(i + 1, j, k) - o, g(i, j + 1, k) - o), g(i, j, k + 1) - o);
      }
  return sum < 0;
}

}  // namespace

HexMesh merge_blocks(std::span<const PointGrid3> blocks, std::span<const SharedFace> shared,
                     std::span<const std::array<std::string, 6>> patch_of, std::vector<std::size_t>* origin) {
  std::vector<std::size_t> offset(blocks.size() + 1, 0);
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const auto n = blocks[b].shape();
    if (n[0] < 2 || n[1] < 2 || n[2] < 2)
      fail(errc::size_mismatch, "block ", b, ": a block needs at least 2 nodes along each direction, got ", n[0], " x ",
           n[1], " x ", n[2]);
    offset[b + 1] = offset[b] + blocks[b].size();
  }
  const auto id = [&](std::size_t b, const std::array<std::size_t, 3>& x) {
    const auto n = blocks[b].shape();
    return offset[b] + (x[0] * n[1] + x[1]) * n[2] + x[2];
  };
  Sets sets(offset.back());
  std::vector<std::array<bool, 6>> is_shared(blocks.size(), std::array<bool, 6>{});
  for (const SharedFace& f : shared) {
    const FaceView p = view(blocks[f.block[0]], f.face[0]), q = view(blocks[f.block[1]], f.face[1]);
    is_shared[f.block[0]][static_cast<std::size_t>(f.face[0])] = true;
    is_shared[f.block[1]][static_cast<std::size_t>(f.face[1])] = true;
    for (std::size_t s = 0; s < p.ns(); ++s)
      for (std::size_t t = 0; t < p.nt(); ++t) {
        const auto o = apply(f.map, s, t, q.ns(), q.nt());
        sets.join(id(f.block[0], p.index(s, t)), id(f.block[1], q.index(o[0], o[1])));
      }
  }
  HexMesh m;
  if (origin) origin->clear();
  std::vector<std::uint32_t> number(offset.back(), std::numeric_limits<std::uint32_t>::max());
  for (std::size_t x = 0; x < offset.back(); ++x) {
    if (sets.find(x) != x) continue;
    if (m.points.size() == std::numeric_limits<std::uint32_t>::max())
      fail(errc::too_large, "a mesh of more than 2^32 - 1 nodes: they are numbered in 32 bits");
    number[x] = static_cast<std::uint32_t>(m.points.size());
    const std::size_t b = static_cast<std::size_t>(std::upper_bound(offset.begin(), offset.end(), x) - offset.begin()) - 1;
    m.points.push_back(blocks[b].data()[x - offset[b]]);
    if (origin) origin->push_back(x);
  }
  // Patches in the order their names first appear, block by block.
  std::vector<std::array<std::int32_t, 6>> patch(blocks.size());
  for (std::size_t b = 0; b < blocks.size(); ++b)
    for (std::size_t f = 0; f < 6; ++f) {
      if (is_shared[b][f]) {
        patch[b][f] = -1;
        continue;
      }
      const std::string& name = patch_of[b][f];
      const auto at = std::find(m.patch_names.begin(), m.patch_names.end(), name);
      patch[b][f] = static_cast<std::int32_t>(at - m.patch_names.begin());
      if (at == m.patch_names.end()) m.patch_names.push_back(name);
    }
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const auto n = blocks[b].shape();
    const bool turn = left_handed(blocks[b]);  // swap bottom and top: every cell right-handed
    const auto node = [&](std::size_t i, std::size_t j, std::size_t k) { return number[sets.find(id(b, {i, j, k}))]; };
    for (std::size_t i = 0; i + 1 < n[0]; ++i)
      for (std::size_t j = 0; j + 1 < n[1]; ++j)
        for (std::size_t k = 0; k + 1 < n[2]; ++k) {
          const std::size_t lo = turn ? k + 1 : k, hi = turn ? k : k + 1;
          m.cells.push_back({node(i, j, lo), node(i + 1, j, lo), node(i + 1, j + 1, lo), node(i, j + 1, lo),
                             node(i, j, hi), node(i + 1, j, hi), node(i + 1, j + 1, hi), node(i, j + 1, hi)});
          const auto on = [&](bool edge, std::size_t f) { return edge ? patch[b][f] : std::int32_t{-1}; };
          const std::int32_t w0 = on(k == 0, 4), w1 = on(k + 2 == n[2], 5);
          m.face_patch.push_back({on(i == 0, 0), on(i + 2 == n[0], 1), on(j == 0, 2), on(j + 2 == n[1], 3),
                                  turn ? w1 : w0, turn ? w0 : w1});
        }
  }
  return m;
}

}  // namespace interpatch::mesh
