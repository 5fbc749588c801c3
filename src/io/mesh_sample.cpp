// A surface sampled into a mesh: in memory (sample_mesh), or for the structured
// formats straight into the file, a block of columns at a time, without the mesh
// in memory (stream_surface).

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "base/parallel.hpp"
#include "base/pipeline.hpp"
#include "interpatch/bspline_surface.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/memory.hpp"
#include "io/finite.hpp"
#include "io/mesh_formats.hpp"
#include "io/mesh_sink.hpp"

namespace interpatch::io {
namespace fs = std::filesystem;

namespace {

using internal::mesh_io::legacy_vtk_head;
using internal::mesh_io::legacy_vtk_point_data;
using internal::quoted;
using internal::mesh_io::to_byte_order;
using internal::mesh_io::vts_count;
using internal::mesh_io::vts_head;
using internal::mesh_io::vts_tail;

// A direction in which a B-spline surface is periodic and the samples span one
// whole period closes: its last row (column) is its first again.
std::array<bool, 2> closed_directions(const Surface& surface, std::span<const double> us, std::span<const double> vs) {
  std::array<bool, 2> closed = {false, false};
  if (const auto* b = dynamic_cast<const BSplineSurface*>(&surface)) {
    const auto domain = b->domain();
    for (const std::size_t a : {0u, 1u}) {
      const std::span<const double> t = a == 0 ? us : vs;
      const double period = domain[a].second - domain[a].first;
      // Parameters made by linspace over a period end on its ends to an ulp or so.
      closed[a] = b->periodic()[a] && t.size() >= 2 && std::abs(std::abs(t.back() - t.front()) - period) <= 1e-12 * period;
    }
  }
  return closed;
}

/// Where the two arrays of a structured surface file (.vts, .vtk) go, and the
/// bytes that stand around them: what stream_structured writes.
struct ArrayLayout {
  std::uint64_t points_at = 0, normals_at = 0, size = 0;
  std::endian order = std::endian::little;
  std::vector<std::pair<std::uint64_t, std::string>> texts;  // (offset, bytes)
};

/// The layout write_vts gives a surface's points and normals.
ArrayLayout vts_layout(std::size_t nu, std::size_t nv) {
  const std::uint64_t vec_bytes = std::uint64_t{24} * nu * nv;
  std::string head = vts_head(nu, nv, 1, true, false) + vts_count(vec_bytes);
  ArrayLayout l;
  l.normals_at = head.size();
  l.points_at = l.normals_at + vec_bytes + 8;
  l.size = l.points_at + vec_bytes + vts_tail.size();
  l.texts = {{0, std::move(head)}, {l.points_at - 8, vts_count(vec_bytes)}, {l.points_at + vec_bytes, std::string(vts_tail)}};
  return l;
}

/// The layout write_legacy_vtk gives them.
ArrayLayout legacy_vtk_layout(std::size_t nu, std::size_t nv) {
  const std::uint64_t vec_bytes = std::uint64_t{24} * nu * nv;
  std::string head = legacy_vtk_head(nu, nv, 1, "surface"), between = legacy_vtk_point_data(nu * nv, true, false);
  ArrayLayout l;
  l.order = std::endian::big;
  l.points_at = head.size();
  l.normals_at = l.points_at + vec_bytes + between.size();
  l.size = l.normals_at + vec_bytes + 1;
  l.texts = {{0, std::move(head)}, {l.points_at + vec_bytes, std::move(between)}, {l.normals_at + vec_bytes, "\n"}};
  return l;
}

// A .vts or .vtk of a surface's mesh (points and normals) without the mesh in
// memory: blocks of whole columns (v values), each a run of both arrays, i fastest.
// Every thread evaluates a few rows of the block and puts them in the file's order
// while the block before is written at its two places in the file; the bytes are
// those of write_surface_mesh(path, sample_mesh(...)).
static_assert(sizeof(Vec3) == 3 * sizeof(double), "a point is three doubles, written as they are");

void stream_structured(const fs::path& path, const ArrayLayout& layout, const Surface& surface,
                       std::span<const double> us, std::span<const double> vs, const progress_callback& progress) {
  const std::size_t nu = us.size(), nv = vs.size(), n = nu * nv;
  const std::array<bool, 2> closed = closed_directions(surface, us, vs);
  // About 2^15 points a block (1.5 MiB of points and normals), pieces of about 2^11:
  // few fresh pages (write_npy_rows).
  constexpr std::size_t block_points = std::size_t{1} << 15, piece_points = std::size_t{1} << 11;
  const std::size_t block_cols = std::clamp<std::size_t>(block_points / nu, 1, nv);
  const std::size_t piece_rows = std::max<std::size_t>(1, piece_points / block_cols);
  const std::size_t blocks = (nv + block_cols - 1) / block_cols, pieces = (nu + piece_rows - 1) / piece_rows;
  require_memory(4 * block_cols * nu + 2 * nu, sizeof(Vec3), "the blocks of the mesh '" + path.string() + "'");
  // Column j of a block, i fastest; not zeroed (every element is written).
  PointGrid points[2] = {PointGrid({block_cols, nu}, for_overwrite), PointGrid({block_cols, nu}, for_overwrite)};
  PointGrid normals[2] = {PointGrid({block_cols, nu}, for_overwrite), PointGrid({block_cols, nu}, for_overwrite)};
  std::vector<Vec3> first_points, first_normals;  // column 0, for the last of a surface closed in v
  const auto grid = surface.normal_grid(us, vs);  // what depends on u alone or v alone, once
  const auto columns = [&](std::size_t b) { return std::pair(b * block_cols, std::min(block_cols, nv - b * block_cols)); };
  const std::string points_of = "the points of " + quoted(path), normals_of = "the normals of " + quoted(path);
  const auto make = [&](std::size_t b, std::size_t p) {
    const auto [j0, m] = columns(b);
    const std::size_t i0 = p * piece_rows, k = std::min(piece_rows, nu - i0);
    // The piece's rows in the grid's order (not zeroed), then put in the file's.
    const auto P = std::make_unique_for_overwrite<Vec3[]>(k * m), N = std::make_unique_for_overwrite<Vec3[]>(k * m);
    grid->evaluate_into(i0, k, j0, m, std::span(P.get(), k * m), std::span(N.get(), k * m));
    // Points and normals of rows i0.. and columns j0..: named by their place in the mesh.
    for (std::size_t i = 0; i < k; ++i) {
      const std::size_t shape[3] = {nu, nv, 3};
      const std::size_t first = ((i0 + i) * nv + j0) * 3;
      internal::require_finite(&P[i * m].x, 3 * m, first, shape, points_of);
      internal::require_finite(&N[i * m].x, 3 * m, first, shape, normals_of);
    }
    Vec3 *to_p = points[b % 2].data(), *to_n = normals[b % 2].data();
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t j = 0; j < m; ++j) {
        to_p[j * nu + i0 + i] = P[i * m + j];
        to_n[j * nu + i0 + i] = N[i * m + j];
      }
    // In the file's byte order here, on every thread (the seams are copied as bytes).
    for (std::size_t j = 0; layout.order != std::endian::native && j < m; ++j)
      for (Vec3* a : {to_p, to_n}) to_byte_order(reinterpret_cast<char*>(a + j * nu + i0), k * sizeof(Vec3), layout.order);
  };
  const auto write = [&](std::ostream& os, std::size_t b) {
    const auto [j0, m] = columns(b);
    Vec3 *P = points[b % 2].data(), *N = normals[b % 2].data();
    for (std::size_t j = 0; closed[0] && j < m; ++j) {
      P[j * nu + nu - 1] = P[j * nu];
      N[j * nu + nu - 1] = N[j * nu];
    }
    if (closed[1] && b == 0) {
      first_points.assign(P, P + nu);
      first_normals.assign(N, N + nu);
    }
    if (closed[1] && j0 + m == nv) {
      std::copy(first_points.begin(), first_points.end(), P + (m - 1) * nu);
      std::copy(first_normals.begin(), first_normals.end(), N + (m - 1) * nu);
    }
    os.seekp(static_cast<std::streamoff>(layout.normals_at + std::uint64_t{24} * j0 * nu));
    os.write(reinterpret_cast<const char*>(N), static_cast<std::streamsize>(m * nu * sizeof(Vec3)));
    os.seekp(static_cast<std::streamoff>(layout.points_at + std::uint64_t{24} * j0 * nu));
    os.write(reinterpret_cast<const char*>(P), static_cast<std::streamsize>(m * nu * sizeof(Vec3)));
    if (progress) progress(static_cast<double>(j0 + m) / static_cast<double>(nv));
  };
  write_atomically(path, [&](std::ostream& os) {
    os << layout.texts.front().second;
    detail::pipeline(
        blocks, n >= detail::parallel_min_work / 16, [&](std::size_t) { return pieces; }, make,
        [&](std::size_t b) { write(os, b); });
    for (std::size_t t = 1; t < layout.texts.size(); ++t) {
      os.seekp(static_cast<std::streamoff>(layout.texts[t].first));
      os << layout.texts[t].second;
    }
  }, layout.size);
}

}  // namespace

SurfaceMesh sample_mesh(const Surface& surface, std::span<const double> us, std::span<const double> vs,
                        const progress_callback& progress) {
  const std::size_t nu = us.size(), nv = vs.size();
  SurfaceMesh mesh{PointGrid({nu, nv}, for_overwrite), PointGrid({nu, nv}, for_overwrite), {false, false}};
  surface.evaluate_normals_into(us, vs, std::span<Vec3>(mesh.points.data(), mesh.points.size()),
                                std::span<Vec3>(mesh.normals.data(), mesh.normals.size()), progress);
  // Points and normals of the last row (column) of a closed direction are copied
  // from the first, so that every format sees one seam.
  mesh.closed = closed_directions(surface, us, vs);
  for (std::size_t j = 0; mesh.closed[0] && j < nv; ++j) {
    mesh.points(nu - 1, j) = mesh.points(0, j);
    mesh.normals(nu - 1, j) = mesh.normals(0, j);
  }
  for (std::size_t i = 0; mesh.closed[1] && i < nu; ++i) {
    mesh.points(i, nv - 1) = mesh.points(i, 0);
    mesh.normals(i, nv - 1) = mesh.normals(i, 0);
  }
  return mesh;
}

void internal::mesh_io::stream_surface(const fs::path& path, const std::string& ext, const Surface& surface,
                                       std::span<const double> us, std::span<const double> vs,
                                       const progress_callback& progress) {
  stream_structured(path, ext == ".vts" ? vts_layout(us.size(), vs.size()) : legacy_vtk_layout(us.size(), vs.size()),
                    surface, us, vs, progress);
}

}  // namespace interpatch::io
