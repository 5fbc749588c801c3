#include "mesh/hex_mesh.hpp"

#include <algorithm>
#include <limits>
#include <unordered_map>

#include "base/text.hpp"

namespace interpatch::mesh {

using detail::fail;

HexMesh structured_hex_mesh(const PointGrid3& nodes) {
  const auto n = nodes.shape();
  if (n[0] < 2 || n[1] < 2 || n[2] < 2)
    fail(errc::size_mismatch, "a hexahedral mesh needs at least 2 nodes along each direction, got ", n[0], " x ",
         n[1], " x ", n[2]);
  if (nodes.size() > std::numeric_limits<std::uint32_t>::max())
    fail(errc::too_large, "a hexahedral mesh of ", nodes.size(), " nodes: at most 2^32 - 1 are numbered");
  HexMesh m;
  m.points.assign(nodes.data(), nodes.data() + nodes.size());
  m.patch_names = {"u0", "u1", "v0", "v1", "w0", "w1"};
  const auto id = [&](std::size_t i, std::size_t j, std::size_t k) {
    return static_cast<std::uint32_t>((i * n[1] + j) * n[2] + k);
  };
  const std::size_t cells = (n[0] - 1) * (n[1] - 1) * (n[2] - 1);
  m.cells.reserve(cells);
  m.face_patch.reserve(cells);
  for (std::size_t i = 0; i + 1 < n[0]; ++i)
    for (std::size_t j = 0; j + 1 < n[1]; ++j)
      for (std::size_t k = 0; k + 1 < n[2]; ++k) {
        m.cells.push_back({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1),
                           id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)});
        m.face_patch.push_back({i == 0 ? 0 : -1, i + 2 == n[0] ? 1 : -1, j == 0 ? 2 : -1, j + 2 == n[1] ? 3 : -1,
                                k == 0 ? 4 : -1, k + 2 == n[2] ? 5 : -1});
      }
  return m;
}

namespace {

std::array<std::uint32_t, 4> face_nodes(const std::array<std::uint32_t, 8>& cell, std::size_t f, bool flipped) {
  const auto& l = hex_faces[f];
  if (flipped) return {cell[l[0]], cell[l[3]], cell[l[2]], cell[l[1]]};
  return {cell[l[0]], cell[l[1]], cell[l[2]], cell[l[3]]};
}

// The volume a cell's faces enclose (triangles about each face's vertex average), in
// the faces' orientation: negative for a left-handed cell.
double signed_volume(const HexMesh& m, const std::array<std::uint32_t, 8>& cell) {
  double v = 0;
  for (std::size_t f = 0; f < 6; ++f) {
    const auto q = face_nodes(cell, f, false);
    const Vec3 c = 0.25 * (m.points[q[0]] + m.points[q[1]] + m.points[q[2]] + m.points[q[3]]);
    for (std::size_t e = 0; e < 4; ++e)
      v += dot(c, cross(m.points[q[e]] - c, m.points[q[(e + 1) % 4]] - c));
  }
  return v / 6;
}

struct Key {
  std::array<std::uint32_t, 4> sorted;
  bool operator==(const Key&) const = default;
};
struct KeyHash {
  std::size_t operator()(const Key& k) const noexcept {
    std::size_t h = 1469598103934665603ull;
    for (std::uint32_t x : k.sorted) h = (h ^ x) * 1099511628211ull;
    return h;
  }
};

}  // namespace

PolyMesh poly_mesh(const HexMesh& m) {
  PolyMesh p;
  double volume = 0;
  for (const auto& c : m.cells) volume += signed_volume(m, c);
  p.flipped = volume < 0;
  // Each face's first cell (the lower number: cells are visited in order) and local face.
  std::unordered_map<Key, std::pair<std::uint32_t, std::uint32_t>, KeyHash> first;
  first.reserve(m.cells.size() * 3);
  struct Internal {
    std::uint32_t owner, neighbour;
    std::array<std::uint32_t, 4> nodes;
  };
  std::vector<Internal> internal;
  internal.reserve(m.cells.size() * 3);
  for (std::uint32_t c = 0; c < m.cells.size(); ++c)
    for (std::uint32_t f = 0; f < 6; ++f) {
      Key k{face_nodes(m.cells[c], f, false)};
      std::sort(k.sorted.begin(), k.sorted.end());
      const auto [it, fresh] = first.try_emplace(k, c, f);
      if (fresh) continue;
      if (it->second.first == std::numeric_limits<std::uint32_t>::max())
        fail(errc::internal, "a face of cell ", c, " is shared by three cells");
      const auto [o, of] = it->second;
      internal.push_back({o, c, face_nodes(m.cells[o], of, p.flipped)});
      it->second.first = std::numeric_limits<std::uint32_t>::max();  // matched
    }
  std::sort(internal.begin(), internal.end(), [](const Internal& a, const Internal& b) {
    return a.owner != b.owner ? a.owner < b.owner : a.neighbour < b.neighbour;
  });
  for (const Internal& f : internal) {
    p.faces.push_back(f.nodes);
    p.owner.push_back(f.owner);
    p.neighbour.push_back(f.neighbour);
  }
  // The boundary, patch by patch, each by owner and local face.
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> by_patch(m.patch_names.size());
  for (const auto& [key, at] : first) {
    if (at.first == std::numeric_limits<std::uint32_t>::max()) continue;
    const std::int32_t patch = m.face_patch[at.first][at.second];
    if (patch < 0) fail(errc::internal, "face ", at.second, " of cell ", at.first, " is on the boundary but in no patch");
    by_patch[static_cast<std::size_t>(patch)].push_back(at);
  }
  for (std::size_t q = 0; q < by_patch.size(); ++q) {
    auto& faces = by_patch[q];
    std::sort(faces.begin(), faces.end());
    p.patches.push_back({m.patch_names[q], p.faces.size(), faces.size()});
    for (const auto& [c, f] : faces) {
      p.faces.push_back(face_nodes(m.cells[c], f, p.flipped));
      p.owner.push_back(c);
    }
  }
  return p;
}

}  // namespace interpatch::mesh
