#include "interpatch/io/csv.hpp"

#include <unistd.h>

#include <atomic>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch::io {
namespace {
namespace fs = std::filesystem;

using test::TempDir;

using test::read_text;

fs::path write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
  return p;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (;;) {
    const auto at = s.find(sep, start);
    out.push_back(s.substr(start, at - start));
    if (at == std::string::npos) return out;
    start = at + 1;
  }
}

double parse_exact(const std::string& s) {
  double v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  EXPECT_TRUE(r.ec == std::errc() && r.ptr == s.data() + s.size()) << "'" << s << "'";
  return v;
}

std::string digits17(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

// --- Reading -----------------------------------------------------------------------

TEST(Csv, ReadsPointsWithoutHeader) {
  TempDir dir;
  const auto pts = read_csv_points(write_text(dir / "p.csv", "1,2,3\n4.5,-5e-3,6E2\n"));
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_EQ(pts[0], (Vec3{1, 2, 3}));
  EXPECT_EQ(pts[1], (Vec3{4.5, -5e-3, 600}));
}

TEST(Csv, SkipsHeaderLine) {
  TempDir dir;
  const auto pts = read_csv_points(write_text(dir / "p.csv", "x,y,z\n1,2,3\n4,5,6\n"), 2);
  ASSERT_EQ(pts.size(), 2u);
  EXPECT_EQ(pts[1], (Vec3{4, 5, 6}));
  // A header with other names and field counts is a header all the same.
  EXPECT_EQ(read_csv_points(write_text(dir / "q.csv", "X coordinate, Y coordinate, Z, label\n1,2,3\n")).size(), 1u);
  // numpy.savetxt(..., header='x,y,z') writes "# x,y,z".
  EXPECT_EQ(read_csv_points(write_text(dir / "r.csv", "# x,y,z\n1,2,3\n")).size(), 1u);
}

TEST(Csv, ToleratesCrlfSpacesTabsSignsQuotesBomAndTrailingBlankLines) {
  TempDir dir;
  const std::string text =
      "\xEF\xBB\xBFx, y, z\r\n"
      " 1 ,\t2\t, 3 \r\n"
      "+4,\"5\",-6\r\n"
      "\r\n"
      "7,8,9"  // no final newline
      "\n\n\n";
  const auto pts = read_csv_points(write_text(dir / "w.csv", text), 3);
  ASSERT_EQ(pts.size(), 3u);
  EXPECT_EQ(pts[0], (Vec3{1, 2, 3}));
  EXPECT_EQ(pts[1], (Vec3{4, 5, -6}));
  EXPECT_EQ(pts[2], (Vec3{7, 8, 9}));
  const auto last = read_csv_points(write_text(dir / "n.csv", "1,2,3\n4,5,6"));
  ASSERT_EQ(last.size(), 2u);
  EXPECT_EQ(last[1], (Vec3{4, 5, 6}));
}

TEST(Csv, SeventeenDigitsReadBackExactly) {
  TempDir dir;
  auto g = test::rng(21);
  std::vector<Vec3> pts;
  std::string text = "x,y,z\n";
  for (int i = 0; i < 500; ++i) {
    Vec3 p = test::random_point(g, std::pow(10.0, test::uniform(g, -30, 30)));
    if (i == 0) p = {0.1, -0.0, std::numeric_limits<double>::denorm_min()};
    if (i == 1) p = {std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(), 1e-300};
    pts.push_back(p);
    text += digits17(p.x) + "," + digits17(p.y) + "," + digits17(p.z) + "\n";
  }
  const auto back = read_csv_points(write_text(dir / "e.csv", text), pts.size());
  ASSERT_EQ(back.size(), pts.size());
  EXPECT_EQ(std::memcmp(back.data(), pts.data(), pts.size() * sizeof(Vec3)), 0);
}

TEST(Csv, UnderflowReadsAsZero) {
  TempDir dir;
  const auto pts = read_csv_points(write_text(dir / "u.csv", "1e-400,-1e-400,2\n"));
  ASSERT_EQ(pts.size(), 1u);
  EXPECT_EQ(pts[0].x, 0.0);
  EXPECT_EQ(pts[0].y, 0.0);
  EXPECT_TRUE(std::signbit(pts[0].y));
}

TEST(Csv, ManyLinesAcrossReadBlocks) {
  TempDir dir;
  std::string text;
  const int n = 120000;  // a few megabytes: several of the reader's blocks
  for (int i = 0; i < n; ++i) text += std::to_string(i) + ".5, " + std::to_string(-i) + ", 1e-3\n";
  const auto pts = read_csv_points(write_text(dir / "m.csv", text), n);
  ASSERT_EQ(pts.size(), static_cast<std::size_t>(n));
  for (int i = 0; i < n; i += 997) EXPECT_EQ(pts[static_cast<std::size_t>(i)], (Vec3{i + 0.5, -1.0 * i, 1e-3}));
  EXPECT_EQ(pts.back(), (Vec3{n - 0.5, -1.0 * (n - 1), 1e-3}));
}

TEST(Csv, NonNumberNamesFileRowAndColumn) {
  TempDir dir;
  const auto p = write_text(dir / "bad.csv", "x,y,z\n1,2,3\n4,abc,6\n");
  EXPECT_ERRC((void)read_csv_points(p), malformed_file, "bad.csv:3:2: 'abc' is not a number");
  // Rows count blank and comment lines: they are line numbers in the file.
  const auto q = write_text(dir / "gap.csv", "1,2,3\n\n# note\n4,5,6x\n");
  EXPECT_ERRC((void)read_csv_points(q), malformed_file, "gap.csv:4:3: '6x' is not a number");
  // A first line with numbers in it is data, not a header.
  const auto r = write_text(dir / "first.csv", "1.0,abc,3\n4,5,6\n");
  EXPECT_ERRC((void)read_csv_points(r), malformed_file, "first.csv:1:2: 'abc' is not a number");
  // Only one header line.
  const auto s = write_text(dir / "two.csv", "x,y,z\nu,v,w\n1,2,3\n");
  EXPECT_ERRC((void)read_csv_points(s), malformed_file, "two.csv:2:1: 'u' is not a number");
  // Decimal commas split fields; a semicolon-separated file is one field.
  const auto t = write_text(dir / "semi.csv", "1;2;3\n");
  EXPECT_ERRC((void)read_csv_points(t), malformed_file, "semi.csv:1:1: '1;2;3' is not a number");
  const auto u = write_text(dir / "empty.csv", "1,,3\n");
  EXPECT_ERRC((void)read_csv_points(u), malformed_file, "empty.csv:1:2: empty field");
}

TEST(Csv, WrongFieldCount) {
  TempDir dir;
  const auto p = write_text(dir / "few.csv", "x,y,z\n1,2,3\n4,5\n");
  EXPECT_ERRC((void)read_csv_points(p), malformed_file, "few.csv:3:3: 2 fields found, 3 expected");
  const auto q = write_text(dir / "many.csv", "1,2,3,4\n");
  EXPECT_ERRC((void)read_csv_points(q), malformed_file, "many.csv:1:4: 4 fields found, 3 expected");
  const auto r = write_text(dir / "trail.csv", "1,2,3,\n");
  EXPECT_ERRC((void)read_csv_points(r), malformed_file, "trail.csv:1:4: 4 fields found, 3 expected");
  const auto s = write_text(dir / "one.csv", "1,2,3\n7\n");
  EXPECT_ERRC((void)read_csv_points(s), malformed_file, "one.csv:2:2: 1 field found, 3 expected");
}

TEST(Csv, NanAndInfAreNotFinite) {
  TempDir dir;
  EXPECT_ERRC((void)read_csv_points(write_text(dir / "n.csv", "x,y,z\n1,nan,3\n")), not_finite,
              "n.csv:2:2: 'nan' is not finite");
  EXPECT_ERRC((void)read_csv_points(write_text(dir / "i.csv", "1,2,-inf\n")), not_finite, "i.csv:1:3: '-inf'");
  EXPECT_ERRC((void)read_csv_points(write_text(dir / "N.csv", "NaN,2,3\n")), not_finite, "N.csv:1:1:");
  EXPECT_ERRC((void)read_csv_points(write_text(dir / "o.csv", "1,1e400,3\n")), not_finite,
              "o.csv:1:2: '1e400' overflows a double");
}

TEST(Csv, CountMismatch) {
  TempDir dir;
  const auto p = write_text(dir / "c.csv", "x,y,z\n1,2,3\n4,5,6\n");
  EXPECT_ERRC((void)read_csv_points(p, 3), size_mismatch, "c.csv: 2 points found, 3 expected");
  EXPECT_ERRC((void)read_csv_points(p, 1), size_mismatch, "c.csv: 2 points found, 1 expected");
  EXPECT_EQ(read_csv_points(p, 2).size(), 2u);
  EXPECT_EQ(read_csv_points(p).size(), 2u);
  const auto e = write_text(dir / "h.csv", "x,y,z\n");
  EXPECT_ERRC((void)read_csv_points(e, 4), size_mismatch, "h.csv: 0 points found, 4 expected");
  EXPECT_TRUE(read_csv_points(e).empty());
  // A huge expected count is not trusted for allocation.
  EXPECT_ERRC((void)read_csv_points(p, std::size_t{1} << 60), size_mismatch, "2 points found");
}

TEST(Csv, UnreadableFile) {
  TempDir dir;
  EXPECT_ERRC((void)read_csv_points(dir / "missing.csv"), file_unreadable, "missing.csv': No such file or directory");
  EXPECT_ERRC((void)read_csv_points(dir.path()), file_unreadable, "it is a directory");
}

TEST(Csv, BinaryFileWithoutNewlinesIsRefused) {
  TempDir dir;
  const auto p = write_text(dir / "blob.csv", std::string((std::size_t{1} << 24) + 100, 'A'));
  EXPECT_ERRC((void)read_csv_points(p), malformed_file, "blob.csv:1: line longer than");
}

// --- Writing ------------------------------------------------------------------------

TEST(Csv, WriteGridTwoAxesRoundTripsExactly) {
  TempDir dir;
  auto g = test::rng(22);
  const std::vector<std::vector<double>> params = {{0.0, 1.0 / 3.0, 1.0}, {0.0, 0.1, 0.7, 1.0}};
  std::vector<Vec3> pts;
  for (int i = 0; i < 12; ++i) pts.push_back(test::random_point(g, 1e3));
  pts[5] = {-0.0, 1e-310, 0.1};
  write_csv_grid(dir / "g.csv", params, pts);
  const std::string text = read_text(dir / "g.csv");
  const auto lines = split(text, '\n');
  ASSERT_EQ(lines.size(), 14u);  // header, 12 rows, empty after the final newline
  EXPECT_EQ(lines[0], "u,v,x,y,z");
  EXPECT_EQ(lines[13], "");
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 4; ++j) {
      const std::size_t q = i * 4 + j;  // C order, u outermost
      const auto f = split(lines[1 + q], ',');
      ASSERT_EQ(f.size(), 5u);
      EXPECT_EQ(parse_exact(f[0]), params[0][i]);
      EXPECT_EQ(parse_exact(f[1]), params[1][j]);
      const Vec3 p{parse_exact(f[2]), parse_exact(f[3]), parse_exact(f[4])};
      EXPECT_EQ(std::memcmp(&p, &pts[q], sizeof(Vec3)), 0) << q;
      EXPECT_EQ(f[2], digits17(pts[q].x));  // exactly printf's %.17g
    }
}

TEST(Csv, WriteGridOneAndThreeAxes) {
  TempDir dir;
  {
    const std::vector<std::vector<double>> params = {{0.0, 0.5, 1.0}};
    const std::vector<Vec3> pts = {{1, 2, 3}, {4, 5, 6}, {7, 8, 9}};
    write_csv_grid(dir / "c.csv", params, pts);
    EXPECT_EQ(read_text(dir / "c.csv"), "t,x,y,z\n0,1,2,3\n0.5,4,5,6\n1,7,8,9\n");
  }
  {
    const std::vector<std::vector<double>> params = {{0.0, 1.0}, {0.0, 1.0}, {0.0, 0.25, 1.0}};
    std::vector<Vec3> pts;
    for (int i = 0; i < 12; ++i) pts.push_back({static_cast<double>(i), 0, 0});
    write_csv_grid(dir / "v.csv", params, pts);
    const auto lines = split(read_text(dir / "v.csv"), '\n');
    ASSERT_EQ(lines.size(), 14u);
    EXPECT_EQ(lines[0], "u,v,w,x,y,z");
    EXPECT_EQ(lines[1], "0,0,0,0,0,0");
    EXPECT_EQ(lines[3], "0,0,1,2,0,0");     // w fastest
    EXPECT_EQ(lines[4], "0,1,0,3,0,0");     // then v
    EXPECT_EQ(lines[7], "1,0,0,6,0,0");     // u outermost
    EXPECT_EQ(lines[12], "1,1,1,11,0,0");
  }
}

TEST(Csv, WrittenGridReadsBackAsPoints) {
  // The x,y,z columns of a written grid, cut out, read back bit for bit.
  TempDir dir;
  auto g = test::rng(23);
  const std::vector<std::vector<double>> params = {{0.0, 0.5, 1.0}, {0.0, 1.0}};
  std::vector<Vec3> pts;
  for (int i = 0; i < 6; ++i) pts.push_back(test::random_point(g, 123.456));
  write_csv_grid(dir / "g.csv", params, pts);
  std::string xyz;
  for (const auto& line : split(read_text(dir / "g.csv"), '\n')) {
    if (line.empty()) continue;
    const auto f = split(line, ',');
    xyz += f[2] + "," + f[3] + "," + f[4] + "\n";
  }
  const auto back = read_csv_points(write_text(dir / "p.csv", xyz), pts.size());
  EXPECT_EQ(std::memcmp(back.data(), pts.data(), pts.size() * sizeof(Vec3)), 0);
}

TEST(Csv, WriteGridSizeMismatch) {
  TempDir dir;
  const std::vector<std::vector<double>> params = {{0.0, 1.0}, {0.0, 0.5, 1.0}};
  const std::vector<Vec3> pts(5);
  EXPECT_ERRC(write_csv_grid(dir / "m.csv", params, pts), size_mismatch, "parameter grid 2x3 has 6 points, 5 given");
  EXPECT_FALSE(fs::exists(dir / "m.csv"));
  const std::vector<std::vector<double>> four(4, std::vector<double>{0.0});
  EXPECT_ERRC(write_csv_grid(dir / "m.csv", four, std::span<const Vec3>(pts.data(), 1)), size_mismatch,
              "4 parameter axes given, 1 to 3 supported");
  EXPECT_ERRC(write_csv_grid(dir / "m.csv", std::span<const std::vector<double>>(), pts), size_mismatch,
              "0 parameter axes");
}

TEST(Csv, WriteGridToMissingDirectory) {
  TempDir dir;
  const std::vector<std::vector<double>> params = {{0.0}};
  const std::vector<Vec3> pts(1);
  EXPECT_ERRC(write_csv_grid(dir / "no" / "g.csv", params, pts), file_unwritable, "does not exist");
}

}  // namespace
}  // namespace interpatch::io
