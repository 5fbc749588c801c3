#include "interpatch/io/csv.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

#include "base/text.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "io/finite.hpp"
#include "io/input_stream.hpp"

namespace interpatch::io {
namespace fs = std::filesystem;

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

enum class parse_status { ok, not_a_number, overflow };

/// A field as a double, locale-independent. Accepts what std::from_chars accepts
/// (including nan and inf, reported by the caller) plus a leading '+' and one pair
/// of surrounding double quotes.
parse_status parse_number(std::string_view f, double& v) {
  if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = trim(f.substr(1, f.size() - 2));
  if (f.size() >= 2 && f.front() == '+' && f[1] != '-' && f[1] != '+') f.remove_prefix(1);
  if (f.empty()) return parse_status::not_a_number;
  const auto r = std::from_chars(f.data(), f.data() + f.size(), v);
  if (r.ptr != f.data() + f.size()) return parse_status::not_a_number;
  if (r.ec == std::errc::result_out_of_range) {
    // from_chars reports both overflow and underflow; underflow is a plain zero.
    const auto e = f.find_first_of("eE");
    if (e != std::string_view::npos && e + 1 < f.size() && f[e + 1] == '-') {
      v = f.front() == '-' ? -0.0 : 0.0;
      return parse_status::ok;
    }
    return parse_status::overflow;
  }
  return r.ec == std::errc() ? parse_status::ok : parse_status::not_a_number;
}

/// Splits a line at commas into at most `max` fields (the count keeps going).
std::size_t split(std::string_view line, std::string_view* fields, std::size_t max) {
  std::size_t n = 0;
  for (;;) {
    const auto comma = line.find(',');
    if (n < max) fields[n] = trim(line.substr(0, comma));
    ++n;
    if (comma == std::string_view::npos) return n;
    line.remove_prefix(comma + 1);
  }
}

/// Reads a stream line by line in large blocks (no per-line allocation).
class LineReader {
 public:
  /// `name` names the stream in messages; `size` is its length when known (0 if not),
  /// so that a small input is read in one small block.
  LineReader(std::istream& in, const std::string& name, std::uintmax_t size)
      : block_(size > 0 && size < max_block ? static_cast<std::size_t>(size) + 1 : max_block), name_(name), in_(in) {}

  /// The next line without its '\n'; nullopt at the end.
  std::optional<std::string_view> next() {
    ++line_;
    for (;;) {
      const auto nl = std::find(buf_.begin() + static_cast<std::ptrdiff_t>(pos_), buf_.end(), '\n');
      if (nl != buf_.end()) {
        const auto end = static_cast<std::size_t>(nl - buf_.begin());
        std::string_view line(buf_.data() + pos_, end - pos_);
        pos_ = end + 1;
        return line;
      }
      if (eof_) {
        if (pos_ == buf_.size()) return std::nullopt;
        std::string_view line(buf_.data() + pos_, buf_.size() - pos_);
        pos_ = buf_.size();
        return line;
      }
      refill();
    }
  }

 private:
  void refill() {
    buf_.erase(0, pos_);
    pos_ = 0;
    const std::size_t old = buf_.size();
    buf_.resize(old + block_);
    errno = 0;
    in_.read(buf_.data() + old, static_cast<std::streamsize>(block_));
    const auto got = static_cast<std::size_t>(in_.gcount());
    buf_.resize(old + got);
    if (in_.bad() || (!in_ && !in_.eof())) {
      const int e = errno;
      detail::fail(errc::file_unreadable, "cannot read '", name_, "': ", e != 0 ? std::strerror(e) : "read error");
    }
    if (got < block_) eof_ = true;
    if (buf_.size() > max_line && buf_.find('\n') == std::string::npos) {
      detail::fail(errc::malformed_file, name_, ":", line_, ": line longer than ", max_line,
                   " bytes; not a text file of points?");
    }
  }

  static constexpr std::size_t max_line = std::size_t{1} << 24;
  static constexpr std::size_t max_block = std::size_t{1} << 20;
  std::size_t block_;
  const std::string& name_;
  std::size_t line_ = 0;
  std::istream& in_;
  std::string buf_;
  std::size_t pos_ = 0;
  bool eof_ = false;
};

std::string excerpt(std::string_view field) {
  if (field.size() > 40) return std::string(field.substr(0, 40)) + "...";
  return std::string(field);
}

/// "%.17g" without the locale: enough digits to read back the same double.
void append_number(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 17);
  out.append(buf, r.ptr);
}

/// The points in `in`, of `size` bytes when known (0 otherwise); `name` names it in
/// messages. What read_csv_points and parse_csv_points share.
std::vector<Vec3> read_csv_stream(std::istream& in, std::uintmax_t size, const std::string& name, std::size_t expected,
                                  bool allow_nan) {
  LineReader reader(in, name, size);

  std::vector<Vec3> points;
  if (expected > 0) {
    // Never trust `expected` for a reservation larger than the file could fill
    // ("0,0,0\n" is the shortest line).
    points.reserve(std::min<std::size_t>(expected, static_cast<std::size_t>(size / 6 + 1)));
  }

  std::size_t count = 0;  // points seen, also past `expected`
  std::size_t row = 0;
  bool first_content = true;
  while (auto line_opt = reader.next()) {
    ++row;
    std::string_view line = *line_opt;
    if (row == 1 && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);  // UTF-8 byte order mark
    if (trim(line).empty()) continue;
    if (trim(line).front() == '#') continue;  // comment (numpy.savetxt writes its header so)

    std::string_view fields[3];
    const std::size_t nfields = split(line, fields, 3);
    double v[3] = {0, 0, 0};
    parse_status st[3] = {};
    const std::size_t checked = std::min<std::size_t>(nfields, 3);
    bool numeric = false;  // some field is, or starts like, a number
    for (std::size_t k = 0; k < checked; ++k) {
      st[k] = parse_number(fields[k], v[k]);
      numeric = numeric || st[k] != parse_status::not_a_number ||
                (!fields[k].empty() && std::isdigit(static_cast<unsigned char>(fields[k].front())));
    }
    if (first_content) {
      first_content = false;
      // A header names the columns: none of its fields is or starts like a number
      // (so "1;2;3", a file with the wrong separator, is reported, not skipped).
      if (!numeric) continue;
    }
    for (std::size_t k = 0; k < checked; ++k) {
      const std::string where = name + ":" + std::to_string(row) + ":" + std::to_string(k + 1);
      if (st[k] == parse_status::not_a_number) {
        if (fields[k].empty()) detail::fail(errc::malformed_file, where, ": empty field, a number expected");
        detail::fail(errc::malformed_file, where, ": '", excerpt(fields[k]), "' is not a number");
      }
      if (st[k] == parse_status::overflow) {
        detail::fail(errc::not_finite, where, ": '", excerpt(fields[k]), "' overflows a double");
      }
      if (!std::isfinite(v[k]) && !(allow_nan && std::isnan(v[k]))) detail::fail(errc::not_finite, where, ": '", excerpt(fields[k]), "' is not finite");
    }
    if (nfields != 3) {
      detail::fail(errc::malformed_file, name, ":", row, ":", std::min<std::size_t>(nfields, 3) + 1, ": ", nfields,
                   nfields == 1 ? " field" : " fields", " found, 3 expected (x,y,z)");
    }
    ++count;
    if (expected == 0 || count <= expected) points.push_back({v[0], v[1], v[2]});
  }
  if (expected > 0 && count != expected) {
    detail::fail(errc::size_mismatch, name, ": ", count, count == 1 ? " point" : " points", " found, ", expected,
                 " expected");
  }
  return points;
}

}  // namespace

std::vector<Vec3> read_csv_points(const fs::path& path, std::size_t expected, bool allow_nan) {
  std::ifstream in = detail::open_input(path);
  std::error_code ec;
  const auto size = fs::file_size(path, ec);
  return read_csv_stream(in, ec ? 0 : size, path.string(), expected, allow_nan);
}

std::vector<Vec3> parse_csv_points(std::string_view text, std::size_t expected, std::string_view name, bool allow_nan) {
  detail::MemoryStream in(text);
  return read_csv_stream(in, text.size(), std::string(name), expected, allow_nan);
}

void write_csv_grid(const fs::path& path, std::span<const std::vector<double>> params,
                    std::span<const Vec3> points) {
  const std::size_t axes = params.size();
  if (axes < 1 || axes > 3) {
    detail::fail(errc::size_mismatch, "cannot write '", path.string(), "': ", axes,
                 " parameter axes given, 1 to 3 supported");
  }
  std::size_t count = 1;
  std::string dims;
  for (std::size_t a = 0; a < axes; ++a) {
    count *= params[a].size();
    dims += (a ? "x" : "") + std::to_string(params[a].size());
  }
  if (count != points.size()) {
    detail::fail(errc::size_mismatch, "cannot write '", path.string(), "': parameter grid ", dims, " has ", count,
                 " points, ", points.size(), " given");
  }

  std::vector<std::size_t> shape;
  for (const auto& p : params) shape.push_back(p.size());
  shape.push_back(3);
  internal::require_finite(&points.data()->x, 3 * points.size(), 0, shape, "'" + path.string() + "'");
  write_atomically(path, [&](std::ostream& os) {
    static constexpr const char* names[] = {"u", "v", "w"};
    std::string out;
    constexpr std::size_t flush_at = std::size_t{1} << 20;
    out.reserve(flush_at + 256);
    // One axis is a curve's, whose parameter is t.
    for (std::size_t a = 0; a < axes; ++a) (out += axes == 1 ? "t" : names[a]) += ',';
    out += "x,y,z\n";
    std::size_t idx[3] = {0, 0, 0};
    for (const Vec3& p : points) {
      for (std::size_t a = 0; a < axes; ++a) {
        append_number(out, params[a][idx[a]]);
        out += ',';
      }
      append_number(out, p.x);
      out += ',';
      append_number(out, p.y);
      out += ',';
      append_number(out, p.z);
      out += '\n';
      // Next index in C order: the last axis fastest.
      for (std::size_t a = axes; a-- > 0;) {
        if (++idx[a] < params[a].size()) break;
        idx[a] = 0;
      }
      if (out.size() >= flush_at) {
        os.write(out.data(), static_cast<std::streamsize>(out.size()));
        out.clear();
      }
    }
    os.write(out.data(), static_cast<std::streamsize>(out.size()));
  });
}

}  // namespace interpatch::io
