#include "io/row_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cstring>

#include "base/excerpt.hpp"
#include "base/text.hpp"

namespace interpatch::io::internal {

namespace fs = std::filesystem;
using detail::fail;

namespace {

double decode(const unsigned char* p, const NpyDtype& d) noexcept {
  unsigned char b[8];
  for (std::size_t i = 0; i < d.size; ++i) b[i] = p[d.big_endian ? d.size - 1 - i : i];
  if (d.size == 4) {
    float f;
    std::memcpy(&f, b, 4);
    return f;
  }
  double x;
  std::memcpy(&x, b, 8);
  return x;
}

// The numbers of one CSV line, separated by commas or white space; false when a field
// is not a number.
bool numbers(const std::string& line, std::vector<double>& out) {
  out.clear();
  const char* p = line.data();
  const char* end = p + line.size();
  while (p < end) {
    while (p < end && (*p == ' ' || *p == '\t' || *p == ',' || *p == '\r')) ++p;
    if (p == end) break;
    if (*p == '+') ++p;  // from_chars takes no leading plus
    double v = 0;
    const auto r = std::from_chars(p, end, v);
    if (r.ec != std::errc() && r.ec != std::errc::result_out_of_range) return false;
    out.push_back(v);
    p = r.ptr;
    if (p < end && !(*p == ' ' || *p == '\t' || *p == ',' || *p == '\r')) return false;
  }
  return true;
}

bool skip(const std::string& line) {
  const auto k = line.find_first_not_of(" \t\r");
  return k == std::string::npos || line[k] == '#';
}

}  // namespace

RowReader::RowReader(const fs::path& path, std::size_t width, std::string what)
    : path_(path), name_(path.string()), width_(width), in_(path, std::ios::binary) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) fail(errc::file_unreadable, "cannot read '", name_, "': it is a directory");
  if (!in_) fail(errc::file_unreadable, "cannot read '", name_, "': ", std::strerror(errno));
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const std::string form = width == 3 ? "(..., 3)" : "(..., 2, 3)";
  if (ext == ".csv") {
    csv_ = true;
    // Counted first, so that the outputs' sizes are known before any work.
    std::string line;
    std::vector<double> v;
    bool first = true;
    for (std::size_t n = 1; std::getline(in_, line); ++n) {
      if (skip(line)) continue;
      if (!numbers(line, v)) {
        if (first) {  // a header line
          first = false;
          continue;
        }
        fail(errc::malformed_file, name_, ":", n, ": expected ", width, " numbers separated by commas, got '",
             detail::excerpt(line), "'");
      }
      first = false;
      if (v.size() != width)
        fail(errc::malformed_file, name_, ":", n, ": expected ", width, " numbers (", what,
             width == 3 ? ": x, y, z" : ": the origin's x, y, z, then the direction's", "), got ", v.size());
      ++count_;
    }
    in_.clear();
    in_.seekg(0);
    shape_ = {count_};
    return;
  }
  if (ext != ".npy") fail(errc::malformed_file, name_, ": ", what, " are read from .npy or .csv files");
  const auto size = static_cast<std::uint64_t>(fs::file_size(path, ec));
  const NpyHeader h = read_npy_header(in_, size, name_);
  const auto d = parse_npy_dtype(h.descr);
  if (!d || d->kind != 'f')
    fail(errc::malformed_file, name_, ": ", what, " are float64 or float32, not '", detail::excerpt(h.descr), "'");
  dtype_ = *d;
  const std::size_t tail = width == 3 ? 1 : 2;
  const bool fits = h.shape.size() >= tail + 1 && h.shape.back() == 3 && (width == 3 || h.shape[h.shape.size() - 2] == 2);
  if (!fits)
    fail(errc::malformed_file, name_, ": ", what, " are an array of shape ", form, ", got ", npy_shape_text(h.shape));
  if (h.fortran_order && h.shape.size() > 1)
    fail(errc::malformed_file, name_, ": ", what, " are read in C order; this array is in Fortran order "
         "(numpy.save(path, numpy.ascontiguousarray(a)) writes it in C order)");
  shape_.assign(h.shape.begin(), h.shape.end() - static_cast<std::ptrdiff_t>(tail));
  count_ = 1;
  for (const std::size_t e : shape_) count_ *= e;
  const std::uint64_t expect = h.data_offset + static_cast<std::uint64_t>(count_) * width * dtype_.size;
  if (size != expect)
    fail(errc::malformed_file, name_, ": the shape ", npy_shape_text(h.shape), " needs ", expect, " bytes, the file has ",
         size);
}

std::size_t RowReader::read(double* dst, std::size_t rows) {
  rows = std::min(rows, count_ - done_);
  if (rows == 0) return 0;
  if (csv_) return csv_rows(dst, rows);
  const std::size_t n = rows * width_;
  bytes_.resize(n * dtype_.size);
  if (!in_.read(reinterpret_cast<char*>(bytes_.data()), static_cast<std::streamsize>(bytes_.size())))
    fail(errc::file_unreadable, "cannot read '", name_, "': it ended early");
  for (std::size_t i = 0; i < n; ++i) dst[i] = decode(&bytes_[i * dtype_.size], dtype_);
  done_ += rows;
  return rows;
}

std::size_t RowReader::csv_rows(double* dst, std::size_t rows) {
  std::string line;
  std::vector<double> v;
  std::size_t got = 0;
  while (got < rows && std::getline(in_, line)) {
    ++line_;
    if (skip(line) || !numbers(line, v) || v.size() != width_) continue;  // the header: the count checked the rest
    std::copy(v.begin(), v.end(), dst + got * width_);
    ++got;
  }
  if (got < rows) fail(errc::file_unreadable, "cannot read '", name_, "': it changed while it was read");
  done_ += got;
  return got;
}

}  // namespace interpatch::io::internal
