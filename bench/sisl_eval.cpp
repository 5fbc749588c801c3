// SISL's whole process for the comparison with `interpatch eval SPEC --grid K -o OUT.npy`
// on an {"type": "interpolate"} spec: read an (n, m, 3) float64 .npy grid (first index
// along u), compute averaged chord parameters, interpolate with s1537 (bicubic),
// evaluate a K x K grid over the domain with s1506 and write it as a (K, K, 3) .npy.
//
//   sisl_eval IN.npy OUT.npy K
//
// Only what this job needs of the NPY format: little-endian float64, C order.

#include <sisl.h>

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

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: sisl_eval IN.npy OUT.npy K\n";
    return 2;
  }
  try {
    const Array grid = read_npy(argv[1]);
    if (grid.shape.size() != 3 || grid.shape[2] != 3 || grid.shape[0] < 4 || grid.shape[1] < 4)
      throw std::runtime_error(std::string(argv[1]) + ": expected an (n, m, 3) grid, n, m >= 4");
    const std::size_t nu = grid.shape[0], nv = grid.shape[1];
    const auto k = static_cast<std::size_t>(std::strtoull(argv[3], nullptr, 10));
    if (k < 2) throw std::runtime_error("K must be at least 2");
    auto pu = interpatch::bench::averaged_chord_parameters(grid.data.data(), nu, nv, 0);
    auto pv = interpatch::bench::averaged_chord_parameters(grid.data.data(), nu, nv, 1);
    // SISL's first parameter direction is the one that runs fastest in memory: v here.
    SISLSurf* surf = nullptr;
    int stat = 0;
    s1537(const_cast<double*>(grid.data.data()), static_cast<int>(nv), static_cast<int>(nu), 3, pv.data(), pu.data(),
          0, 0, 0, 0, 4, 4, 1, 1, &surf, &stat);
    if (stat < 0 || !surf) throw std::runtime_error("s1537 failed with status " + std::to_string(stat));
    auto vs = linspace(surf->et1[surf->ik1 - 1], surf->et1[surf->in1], k);
    auto us = linspace(surf->et2[surf->ik2 - 1], surf->et2[surf->in2], k);
    std::vector<double> out(k * k * 3);
    s1506(surf, 0, static_cast<int>(k), vs.data(), static_cast<int>(k), us.data(), out.data(), nullptr, &stat);
    freeSurf(surf);
    if (stat < 0) throw std::runtime_error("s1506 failed with status " + std::to_string(stat));
    write_npy(argv[2], {k, k, 3}, out.data());
  } catch (const std::exception& e) {
    std::cerr << "sisl_eval: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
