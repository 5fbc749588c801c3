// SISL's whole process for the comparison with `interpatch eval SPEC --grid K -o OUT.npy`.
//
//   sisl_eval IN.npy OUT.npy K
//
// on an {"type": "interpolate"} spec: read an (n, m, 3) float64 .npy grid (first index
// along u), compute averaged chord parameters, interpolate with s1537 (bicubic),
// evaluate a K x K grid over the domain with s1506 and write it as a (K, K, 3) .npy.
//
//   sisl_eval --coons V0.npy V1.npy U0.npy U1.npy OUT.npy K
//
// on a {"type": "coons"} spec of four {"interpolate": {"npy": ...}} curves: read the
// four (n, 3) point lists (v0 = S(u, 0), v1 = S(u, 1), u0 = S(0, v), u1 = S(1, v)),
// interpolate each with s1357 at chord parameters, make the patch with s1390 (as
// bench/compare's in-library coons job does), evaluate K x K points with s1506 and
// write them as a (K, K, 3) .npy, first index along u.
//
// Only what these jobs need of the NPY format: little-endian float64, C order.

#include <sisl.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "grid_params.hpp"
#include "sisl_coons.hpp"

namespace {

struct Array {
  std::vector<std::size_t> shape;
  std::vector<double> data;
};

std::size_t header_field_end(const std::string& h, std::size_t from) {
  const std::size_t e = h.find_first_of(",}", from);
  if (e == std::string::npos) throw std::runtime_error("npy header: unterminated field");
  return e;
}

Array read_npy(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  char magic[8];
  in.read(magic, 8);
  if (!in || std::memcmp(magic, "\x93NUMPY", 6) != 0) throw std::runtime_error(path + ": not a .npy file");
  std::size_t header_len = 0;
  if (magic[6] == 1) {
    unsigned char b[2];
    in.read(reinterpret_cast<char*>(b), 2);
    header_len = b[0] | (std::size_t{b[1]} << 8);
  } else {
    unsigned char b[4];
    in.read(reinterpret_cast<char*>(b), 4);
    header_len = b[0] | (std::size_t{b[1]} << 8) | (std::size_t{b[2]} << 16) | (std::size_t{b[3]} << 24);
  }
  std::string h(header_len, '\0');
  in.read(h.data(), static_cast<std::streamsize>(header_len));
  if (!in) throw std::runtime_error(path + ": truncated header");
  if (h.find("'descr': '<f8'") == std::string::npos) throw std::runtime_error(path + ": only '<f8' data is read");
  const std::size_t fo = h.find("'fortran_order':");
  if (fo == std::string::npos || h.substr(fo, header_field_end(h, fo) - fo).find("False") == std::string::npos)
    throw std::runtime_error(path + ": only C order is read");
  const std::size_t s0 = h.find('(', h.find("'shape':")), s1 = h.find(')', s0);
  if (s0 == std::string::npos || s1 == std::string::npos) throw std::runtime_error(path + ": no shape");
  Array a;
  std::size_t count = 1;
  for (std::size_t p = s0 + 1; p < s1;) {
    char* end = nullptr;
    const unsigned long long v = std::strtoull(h.c_str() + p, &end, 10);
    const auto q = static_cast<std::size_t>(end - h.c_str());
    if (q == p) break;
    a.shape.push_back(static_cast<std::size_t>(v));
    count *= static_cast<std::size_t>(v);
    p = h.find_first_not_of(", ", q);
  }
  a.data.resize(count);
  in.read(reinterpret_cast<char*>(a.data.data()), static_cast<std::streamsize>(count * sizeof(double)));
  if (!in) throw std::runtime_error(path + ": truncated data");
  return a;
}

void write_npy(const std::string& path, const std::vector<std::size_t>& shape, const double* data) {
  std::string h = "{'descr': '<f8', 'fortran_order': False, 'shape': (";
  std::size_t count = 1;
  for (std::size_t s : shape) {
    h += std::to_string(s) + ", ";
    count *= s;
  }
  h += "), }";
  // Magic (6) + version (2) + length (2) + header + '\n' padded to 64 bytes.
  while ((10 + h.size() + 1) % 64 != 0) h += ' ';
  h += '\n';
  std::ofstream out(path, std::ios::binary);
  out.write("\x93NUMPY\x01\x00", 8);
  const unsigned char len[2] = {static_cast<unsigned char>(h.size() & 0xff), static_cast<unsigned char>(h.size() >> 8)};
  out.write(reinterpret_cast<const char*>(len), 2);
  out << h;
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(count * sizeof(double)));
  if (!out) throw std::runtime_error(path + ": write failed");
}

std::vector<double> linspace(double a, double b, std::size_t n) {
  std::vector<double> t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = a + (b - a) * static_cast<double>(i) / static_cast<double>(n - 1);
  t.back() = b;
  return t;
}

std::vector<double> domain_linspace(const double* knots, int order, int count, std::size_t n) {
  return linspace(knots[order - 1], knots[count], n);
}

std::size_t grid_count(const char* text) {
  const auto k = static_cast<std::size_t>(std::strtoull(text, nullptr, 10));
  if (k < 2) throw std::runtime_error("K must be at least 2");
  return k;
}

void interpolate_grid(const std::string& in, const std::string& out_path, std::size_t k) {
  const Array grid = read_npy(in);
  if (grid.shape.size() != 3 || grid.shape[2] != 3 || grid.shape[0] < 4 || grid.shape[1] < 4)
    throw std::runtime_error(in + ": expected an (n, m, 3) grid, n, m >= 4");
  const std::size_t nu = grid.shape[0], nv = grid.shape[1];
  auto pu = interpatch::bench::averaged_chord_parameters(grid.data.data(), nu, nv, 0);
  auto pv = interpatch::bench::averaged_chord_parameters(grid.data.data(), nu, nv, 1);
  // SISL's first parameter direction is the one that runs fastest in memory: v here.
  SISLSurf* surf = nullptr;
  int stat = 0;
  s1537(const_cast<double*>(grid.data.data()), static_cast<int>(nv), static_cast<int>(nu), 3, pv.data(), pu.data(), 0,
        0, 0, 0, 4, 4, 1, 1, &surf, &stat);
  if (stat < 0 || !surf) throw std::runtime_error("s1537 failed with status " + std::to_string(stat));
  auto vs = domain_linspace(surf->et1, surf->ik1, surf->in1, k);
  auto us = domain_linspace(surf->et2, surf->ik2, surf->in2, k);
  std::vector<double> out(k * k * 3);
  s1506(surf, 0, static_cast<int>(k), vs.data(), static_cast<int>(k), us.data(), out.data(), nullptr, &stat);
  freeSurf(surf);
  if (stat < 0) throw std::runtime_error("s1506 failed with status " + std::to_string(stat));
  write_npy(out_path, {k, k, 3}, out.data());
}

// paths: v0, v1, u0, u1.
void coons(const std::array<std::string, 4>& paths, const std::string& out_path, std::size_t k) {
  std::array<Array, 4> sides;
  for (std::size_t e = 0; e < 4; ++e) {
    sides[e] = read_npy(paths[e]);
    if (sides[e].shape.size() != 2 || sides[e].shape[1] != 3 || sides[e].shape[0] < 4)
      throw std::runtime_error(paths[e] + ": expected an (n, 3) list of points, n >= 4");
  }
  // s1390 takes them around the patch: v0, u1, v1, u0.
  constexpr std::array<std::size_t, 4> around{0, 3, 1, 2};
  std::array<SISLCurve*, 4> curves{};
  std::vector<double> params;
  for (std::size_t e = 0; e < 4; ++e)
    curves[e] = interpatch::bench::sisl_interpolate_curve(sides[around[e]].data.data(), sides[around[e]].shape[0], params);
  SISLSurf* surf = interpatch::bench::sisl_coons_patch(curves);
  for (SISLCurve* c : curves) freeCurve(c);
  // The patch's first parameter is u, the one s1506 runs fastest: the grid comes
  // out u-fastest and is written u-slowest, as interpatch writes it.
  auto us = domain_linspace(surf->et1, surf->ik1, surf->in1, k);
  auto vs = domain_linspace(surf->et2, surf->ik2, surf->in2, k);
  std::vector<double> grid(k * k * 3), out(k * k * 3);
  int stat = 0;
  s1506(surf, 0, static_cast<int>(k), us.data(), static_cast<int>(k), vs.data(), grid.data(), nullptr, &stat);
  freeSurf(surf);
  if (stat < 0) throw std::runtime_error("s1506 failed with status " + std::to_string(stat));
  for (std::size_t j = 0; j < k; ++j)
    for (std::size_t i = 0; i < k; ++i)
      for (std::size_t c = 0; c < 3; ++c) out[3 * (i * k + j) + c] = grid[3 * (j * k + i) + c];
  write_npy(out_path, {k, k, 3}, out.data());
}

}  // namespace

int main(int argc, char** argv) {
  try {
    if (argc == 8 && std::string(argv[1]) == "--coons") {
      coons({argv[2], argv[3], argv[4], argv[5]}, argv[6], grid_count(argv[7]));
    } else if (argc == 4) {
      interpolate_grid(argv[1], argv[2], grid_count(argv[3]));
    } else {
      std::cerr << "usage: sisl_eval IN.npy OUT.npy K\n"
                   "       sisl_eval --coons V0.npy V1.npy U0.npy U1.npy OUT.npy K\n";
      return 2;
    }
  } catch (const std::exception& e) {
    std::cerr << "sisl_eval: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
