#include "io/blocks_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "base/text.hpp"
#include "interpatch/io/outputs.hpp"
#include "io/box.hpp"

namespace interpatch::io::internal {

using detail::cat;
using detail::fail;

namespace {

constexpr const char* axis[] = {"u", "v", "w"};

// Union-find over the blocks' directions (3 b + d), each with its parity against its
// root: whether it runs the other way.
struct Ties {
  std::vector<std::size_t> parent;
  std::vector<bool> flip;  // against the parent
  explicit Ties(std::size_t n) : parent(n), flip(n, false) { std::iota(parent.begin(), parent.end(), std::size_t{0}); }
  std::pair<std::size_t, bool> find(std::size_t x) {
    bool f = false;
    std::size_t r = x;
    while (parent[r] != r) {
      f = f != flip[r];
      r = parent[r];
    }
    return {r, f};
  }
  // x and y tied, y running the other way when `reversed`; false if that contradicts.
  bool join(std::size_t x, std::size_t y, bool reversed) {
    const auto [rx, fx] = find(x);
    const auto [ry, fy] = find(y);
    if (rx == ry) return (fx != fy) == reversed;
    const std::size_t lo = std::min(rx, ry), hi = std::max(rx, ry);
    parent[hi] = lo;
    flip[hi] = (fx != fy) != reversed;
    return true;
  }
};

// The face's directions (s, t) in block terms.
std::array<std::size_t, 2> face_dirs(int face) {
  const auto d = static_cast<std::size_t>(face / 2);
  return {d == 0 ? 1u : 0u, d == 2 ? 1u : 2u};
}

std::string where(const BlockSet& set, std::size_t b, std::size_t d) {
  return cat("/blocks/", b, "/sampling/", axis[d], " (", set.names[b], ")");
}

// A grading as its class sees it: first and last swap, and the ratio inverts, for a
// direction that runs the other way.
Grading turned(Grading g, bool reversed) {
  if (!reversed) return g;
  std::swap(g.first, g.last);
  if (g.ratio != 0) g.ratio = 1 / g.ratio;
  return g;
}

bool same_distribution(const Grading& a, const Grading& b) {
  return a.ratio == b.ratio && a.first == b.first && a.last == b.last && a.max_growth == b.max_growth;
}

// The classes of tied directions, each with the one count and grading its members give.
std::vector<mesh::DirectionClass> tie(const BlockSet& set, std::span<const mesh::SharedFace> shared) {
  const std::size_t nb = set.blocks.size();
  Ties ties(3 * nb);
  for (const mesh::SharedFace& f : shared) {
    const auto a = face_dirs(f.face[0]), b = face_dirs(f.face[1]);
    // Face 0's s runs along face 1's s (or t, transposed), flipped or not; t likewise.
    const std::size_t s_to = f.map.transpose ? b[1] : b[0], t_to = f.map.transpose ? b[0] : b[1];
    const bool s_rev = f.map.transpose ? f.map.flip_t : f.map.flip_s, t_rev = f.map.transpose ? f.map.flip_s : f.map.flip_t;
    for (const auto& [from, to, rev] : {std::tuple{a[0], s_to, s_rev}, std::tuple{a[1], t_to, t_rev}})
      if (!ties.join(3 * f.block[0] + from, 3 * f.block[1] + to, rev))
        fail(errc::block_mismatch, where(set, f.block[0], from), " is tied to itself running the other way across "
             "the faces the blocks share; a structured mesh cannot run both ways");
  }
  std::vector<mesh::DirectionClass> classes;
  std::vector<std::size_t> class_of(3 * nb, 0);
  for (std::size_t x = 0; x < 3 * nb; ++x) {
    const auto [root, f] = ties.find(x);
    if (root == x) {
      class_of[x] = classes.size();
      classes.push_back({{}, {}, cat(set.names[x / 3], " ", axis[x % 3])});
    }
    (void)f;
  }
  for (std::size_t x = 0; x < 3 * nb; ++x) {
    const auto [root, reversed] = ties.find(x);
    mesh::DirectionClass& c = classes[class_of[root]];
    c.members.push_back({x / 3, x % 3, reversed});
  }
  // Counts and gradings: what the members' samplings say must agree.
  for (mesh::DirectionClass& c : classes) {
    const mesh::DirectionMember* counted = nullptr;
    const mesh::DirectionMember* graded = nullptr;
    for (const mesh::DirectionMember& m : c.members) {
      const auto& s = set.blocks[m.block].sampling;
      if (!s) continue;
      const Grading g = turned((*s)[m.dir], m.reversed);
      if (g.count != 0) {
        if (counted && g.count != c.grading.count)
          fail(errc::block_mismatch, where(set, m.block, m.dir), " has count ", g.count, " and ",
               where(set, counted->block, counted->dir), " count ", c.grading.count,
               "; they are tied across the faces the blocks share: give them one count");
        c.grading.count = g.count;
        counted = &m;
      }
      if (g.graded()) {
        if (graded && !same_distribution(g, c.grading))
          fail(errc::block_mismatch, where(set, m.block, m.dir), " and ", where(set, graded->block, graded->dir),
               " grade directions tied across the faces the blocks share, differently; grade one of them",
               m.reversed != graded->reversed ? " (they run opposite ways: one's first is the other's last)" : "");
        const std::size_t count = c.grading.count;
        c.grading = g;
        c.grading.count = count;
        graded = &m;
      }
    }
    if (c.grading.count == 0) c.grading.count = default_volume_resolution.nu;
    // The class runs the way of its first member; name it by a graded or counted one.
    if (graded) c.name = cat(set.names[graded->block], " ", axis[graded->dir]);
  }
  return classes;
}

double default_tolerance(std::span<const VolumeJacobians> corners) {
  Box box;
  for (const VolumeJacobians& g : corners)
    for (std::size_t i = 0; i < g.points.size(); ++i) box.add(g.points.data()[i]);
  return 1e-9 * box.diagonal();
}

}  // namespace

BlocksMesh mesh_blocks(const Construction& c, const progress_callback& progress) {
  const BlockSet& set = *c.blocks;
  BlocksMesh r;
  std::vector<const Volume*> volumes;
  for (const Construction& b : set.blocks) volumes.push_back(&volume_evaluator(b));
  // Which faces meet, by their corners; node for node once the nodes are placed.
  std::vector<PointGrid3> coarse;
  std::vector<VolumeJacobians> corners;
  for (const Volume* v : volumes) {
    const auto dom = v->domain();
    const double us[] = {dom[0].first, dom[0].second}, vs[] = {dom[1].first, dom[1].second},
                 ws[] = {dom[2].first, dom[2].second};
    corners.push_back({v->evaluate(us, vs, ws), {}});
    coarse.push_back(corners.back().points);
  }
  r.tolerance = set.tolerance > 0 ? set.tolerance : default_tolerance(corners);
  r.classes = tie(set, mesh::shared_faces(coarse, r.tolerance));
  const mesh::GradedBlocks g = mesh::graded_blocks(volumes, r.classes);
  r.report = g.report;
  std::vector<PointGrid3> nodes;
  for (std::size_t b = 0; b < volumes.size(); ++b) {
    const auto& p = g.params[b];
    r.grids.push_back(volumes[b]->evaluate_jacobians(p[0], p[1], p[2], progress));
    nodes.push_back(r.grids.back().points);
  }
  r.shared = mesh::shared_faces(nodes, r.tolerance);
  for (const mesh::SharedFace& f : r.shared)
    for (int side = 0; side < 2; ++side) {
      const std::size_t b = f.block[side];
      const auto face = static_cast<std::size_t>(f.face[side]);
      const std::string fallback = cat(set.names[b], "_", mesh::block_face_names[face]);
      if (set.patches[b][face] != fallback)
        fail(errc::block_mismatch, "/patches/", set.patches[b][face], " names ", fallback,
             ", which another block shares: it is inside the mesh, not on its boundary");
    }
  std::vector<std::size_t> origin;
  r.hex = mesh::merge_blocks(nodes, r.shared, set.patches, &origin);
  // det J at each merged node, from the block whose node it kept.
  std::vector<std::size_t> offset{0};
  for (const PointGrid3& n : nodes) offset.push_back(offset.back() + n.size());
  r.jacobian.reserve(origin.size());
  for (const std::size_t x : origin) {
    const auto b = static_cast<std::size_t>(std::upper_bound(offset.begin(), offset.end(), x) - offset.begin()) - 1;
    r.jacobian.push_back(r.grids[b].determinants.data()[x - offset[b]]);
  }
  return r;
}

}  // namespace interpatch::io::internal
