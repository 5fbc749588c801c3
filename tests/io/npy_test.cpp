#include "interpatch/io/npy.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "npy_util.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch::io {
namespace {
namespace fs = std::filesystem;

using test::le_bytes;
using test::make_npy;
using test::TempDir;

std::string read_bytes(const fs::path& p) { return test::read_text(p); }
using test::write_bytes;

template <class T>
std::string be_bytes(const std::vector<T>& v) {
  std::string s = le_bytes(v);
  for (std::size_t i = 0; i < s.size(); i += sizeof(T)) std::reverse(s.begin() + static_cast<std::ptrdiff_t>(i), s.begin() + static_cast<std::ptrdiff_t>(i + sizeof(T)));
  return s;
}

std::vector<double> iota_values(std::size_t n, double scale = 0.25) {
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = scale * static_cast<double>(i) - 3.0;
  return v;
}

// --- Round trips -------------------------------------------------------------

TEST(Npy, RoundTripIsBitExact) {
  TempDir dir;
  auto g = test::rng(11);
  std::vector<double> data(4 * 5 * 3);
  for (double& v : data) v = test::uniform(g, -1e6, 1e6);
  // Values that text formats mangle: signed zero, subnormal, extremes.
  data[0] = -0.0;
  data[1] = std::numeric_limits<double>::denorm_min();
  data[2] = std::numeric_limits<double>::max();
  data[3] = std::numeric_limits<double>::lowest();
  data[4] = 0.1;
  const std::vector<std::size_t> shape = {4, 5, 3};
  write_npy(dir / "a.npy", shape, data);
  const NpyArray a = read_npy(dir / "a.npy");
  EXPECT_EQ(a.shape, shape);
  ASSERT_EQ(a.data.size(), data.size());
  EXPECT_EQ(std::memcmp(a.data.data(), data.data(), data.size() * sizeof(double)), 0);
}

TEST(Npy, ReadsIntoTheCallersMemory) {
  TempDir dir;
  std::vector<double> data(2 * 3 * 3);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = 0.5 * static_cast<double>(i) - 3;
  const std::vector<std::size_t> shape = {2, 3, 3};
  write_npy(dir / "p.npy", shape, data);
  std::vector<double> mine;
  std::vector<std::size_t> seen;
  const auto got = read_npy_into(dir / "p.npy", [&](std::span<const std::size_t> s, std::size_t count) {
    seen.assign(s.begin(), s.end());
    mine.resize(count);
    return mine.data();
  });
  EXPECT_EQ(got, shape);
  EXPECT_EQ(seen, shape);  // told the shape before any value is read
  EXPECT_EQ(mine, data);
  EXPECT_EQ(read_npy(dir / "p.npy").data, mine);  // the same code path as read_npy
  // A destination that refuses the shape stops the read with its own error.
  EXPECT_ERRC((void)read_npy_into(dir / "p.npy",
                                  [](std::span<const std::size_t>, std::size_t) -> double* {
                                    throw interpatch::error(errc::size_mismatch, "not a list of points");
                                  }),
              size_mismatch, "not a list of points");
}

TEST(Npy, WrittenHeaderIsVersion1LittleEndianPaddedTo64) {
  TempDir dir;
  const std::vector<std::size_t> shape = {2, 3};
  const auto data = iota_values(6);
  write_npy(dir / "h.npy", shape, data);
  const std::string bytes = read_bytes(dir / "h.npy");
  ASSERT_GE(bytes.size(), 10u);
  EXPECT_EQ(bytes.substr(0, 6), "\x93NUMPY");
  EXPECT_EQ(bytes[6], 1);
  EXPECT_EQ(bytes[7], 0);
  const std::size_t hlen = static_cast<unsigned char>(bytes[8]) | (static_cast<std::size_t>(static_cast<unsigned char>(bytes[9])) << 8);
  EXPECT_EQ((10 + hlen) % 64, 0u);
  const std::string header = bytes.substr(10, hlen);
  EXPECT_EQ(header.back(), '\n');
  EXPECT_NE(header.find("'descr': '<f8'"), std::string::npos) << header;
  EXPECT_NE(header.find("'fortran_order': False"), std::string::npos) << header;
  EXPECT_NE(header.find("'shape': (2, 3)"), std::string::npos) << header;
  EXPECT_EQ(bytes.size(), 10 + hlen + 6 * 8);
  EXPECT_EQ(bytes.substr(10 + hlen), le_bytes(data));
}

TEST(Npy, RoundTripScalarOneDimensionalAndEmpty) {
  TempDir dir;
  {
    const std::vector<std::size_t> shape = {};
    const std::vector<double> data = {42.5};
    write_npy(dir / "s.npy", shape, data);
    const auto a = read_npy(dir / "s.npy");
    EXPECT_TRUE(a.shape.empty());
    EXPECT_EQ(a.data, data);
    EXPECT_NE(read_bytes(dir / "s.npy").find("'shape': ()"), std::string::npos);
  }
  {
    const std::vector<std::size_t> shape = {7};
    const auto data = iota_values(7);
    write_npy(dir / "v.npy", shape, data);
    const auto a = read_npy(dir / "v.npy");
    EXPECT_EQ(a.shape, shape);
    EXPECT_EQ(a.data, data);
    EXPECT_NE(read_bytes(dir / "v.npy").find("'shape': (7,)"), std::string::npos);
  }
  {
    const std::vector<std::size_t> shape = {0, 3};
    write_npy(dir / "e.npy", shape, std::span<const double>());
    const auto a = read_npy(dir / "e.npy");
    EXPECT_EQ(a.shape, shape);
    EXPECT_TRUE(a.data.empty());
  }
}

TEST(Npy, RoundTripLargeArray) {
  // Larger than the writer's chunk and the reader's buffers.
  TempDir dir;
  const std::vector<std::size_t> shape = {300, 400, 3};
  auto g = test::rng(12);
  std::vector<double> data(300 * 400 * 3);
  for (double& v : data) v = test::uniform(g);
  write_npy(dir / "big.npy", shape, data);
  const auto a = read_npy(dir / "big.npy");
  EXPECT_EQ(a.shape, shape);
  EXPECT_TRUE(a.data == data);
}

TEST(Npy, RoundTripOfFilesReadInPiecesIsBitExact) {
  // Data blocks of 8 MiB and more are read in pieces of 1 MiB by both threads: sizes
  // just above that, not whole pieces, with distinct values, so that a piece read at
  // the wrong offset or left out shows.
  constexpr std::size_t threshold = std::size_t{8} << 20, piece = std::size_t{1} << 20;
  TempDir dir;
  auto g = test::rng(13);
  using Shape = std::vector<std::size_t>;
  for (const Shape& shape : {Shape{350001, 3}, Shape{1100001}}) {
    const std::size_t count = shape.size() == 2 ? shape[0] * shape[1] : shape[0];
    SCOPED_TRACE(std::to_string(count) + " values");
    ASSERT_GT(count * sizeof(double), threshold);
    ASSERT_NE(count * sizeof(double) % piece, 0u);
    std::vector<double> data(count);
    for (std::size_t i = 0; i < count; ++i) data[i] = static_cast<double>(i) + test::uniform(g, 0, 0.5);
    write_npy(dir / "big.npy", shape, data);
    const NpyArray a = read_npy(dir / "big.npy");
    EXPECT_EQ(a.shape, shape);
    ASSERT_EQ(a.data.size(), count);
    EXPECT_EQ(std::memcmp(a.data.data(), data.data(), count * sizeof(double)), 0);
    std::vector<double> mine;
    EXPECT_EQ(read_npy_into(dir / "big.npy",
                            [&](std::span<const std::size_t>, std::size_t n) {
                              mine.assign(n, -1.0);
                              return mine.data();
                            }),
              shape);
    ASSERT_EQ(mine.size(), count);
    EXPECT_EQ(std::memcmp(mine.data(), data.data(), count * sizeof(double)), 0);
  }
  // Big-endian behind a version 2 header: the pieces are found from the end of the
  // file and swapped after they are read.
  const std::size_t count = threshold / sizeof(double) + 1;
  std::vector<double> data(count);
  for (std::size_t i = 0; i < count; ++i) data[i] = -static_cast<double>(i) - test::uniform(g, 0, 0.5);
  const std::string dict = "{'descr': '>f8', 'fortran_order': False, 'shape': (" + std::to_string(count) + ",), }";
  write_bytes(dir / "be.npy", make_npy(dict, be_bytes(data), 2));
  const NpyArray a = read_npy(dir / "be.npy");
  ASSERT_EQ(a.data.size(), count);
  EXPECT_EQ(std::memcmp(a.data.data(), data.data(), count * sizeof(double)), 0);
}

// --- Hand-made files in the variants NumPy produces ------------------------------

TEST(Npy, ReadsFloat32Widened) {
  TempDir dir;
  const std::vector<float> f = {1.5f, -2.25f, 0.1f, 3e38f, -0.0f, 7.0f};
  write_bytes(dir / "f4.npy", make_npy("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }", le_bytes(f)));
  const auto a = read_npy(dir / "f4.npy");
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{2, 3}));
  ASSERT_EQ(a.data.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(a.data[i], static_cast<double>(f[i])) << i;
  EXPECT_TRUE(std::signbit(a.data[4]));
}

TEST(Npy, ReadsBigEndianFloat64AndFloat32) {
  TempDir dir;
  const auto d = iota_values(12, 0.3);
  write_bytes(dir / "be8.npy", make_npy("{'descr': '>f8', 'fortran_order': False, 'shape': (4, 3), }", be_bytes(d)));
  const auto a = read_npy(dir / "be8.npy");
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{4, 3}));
  EXPECT_EQ(a.data, d);

  const std::vector<float> f = {1.0f, 2.5f, -3.75f};
  write_bytes(dir / "be4.npy", make_npy("{'descr': '>f4', 'fortran_order': False, 'shape': (3,), }", be_bytes(f)));
  const auto b = read_npy(dir / "be4.npy");
  EXPECT_EQ(b.data, (std::vector<double>{1.0, 2.5, -3.75}));
}

TEST(Npy, ReadsNativeByteOrder) {
  TempDir dir;
  const auto d = iota_values(3);
  std::string raw(reinterpret_cast<const char*>(d.data()), d.size() * sizeof(double));
  write_bytes(dir / "n.npy", make_npy("{'descr': '=f8', 'fortran_order': False, 'shape': (3,), }", raw));
  EXPECT_EQ(read_npy(dir / "n.npy").data, d);
}

TEST(Npy, FortranOrderIsTransposedToCOrder) {
  TempDir dir;
  // a[i][j] = 10 i + j for shape (2, 3); Fortran order stores i fastest.
  const std::vector<double> fortran = {0, 10, 1, 11, 2, 12};
  write_bytes(dir / "f.npy", make_npy("{'descr': '<f8', 'fortran_order': True, 'shape': (2, 3), }", le_bytes(fortran)));
  const auto a = read_npy(dir / "f.npy");
  EXPECT_EQ(a.shape, (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(a.data, (std::vector<double>{0, 1, 2, 10, 11, 12}));
}

TEST(Npy, FortranOrderRank3Float32BigEndian) {
  TempDir dir;
  const std::size_t n0 = 3, n1 = 4, n2 = 5;
  std::vector<float> fortran;  // value 100 i + 10 j + k, stored with i fastest
  for (std::size_t k = 0; k < n2; ++k)
    for (std::size_t j = 0; j < n1; ++j)
      for (std::size_t i = 0; i < n0; ++i) fortran.push_back(static_cast<float>(100 * i + 10 * j + k));
  write_bytes(dir / "f3.npy",
              make_npy("{'shape': (3, 4, 5), 'fortran_order': True, 'descr': '>f4'}", be_bytes(fortran)));
  const auto a = read_npy(dir / "f3.npy");
  ASSERT_EQ(a.shape, (std::vector<std::size_t>{3, 4, 5}));
  for (std::size_t i = 0; i < n0; ++i)
    for (std::size_t j = 0; j < n1; ++j)
      for (std::size_t k = 0; k < n2; ++k)
        EXPECT_EQ(a.data[(i * n1 + j) * n2 + k], static_cast<double>(100 * i + 10 * j + k));
}

TEST(Npy, FortranOrderOneDimensionalIsPlain) {
  TempDir dir;
  const auto d = iota_values(5);
  write_bytes(dir / "f1.npy", make_npy("{'descr': '<f8', 'fortran_order': True, 'shape': (5,), }", le_bytes(d)));
  EXPECT_EQ(read_npy(dir / "f1.npy").data, d);
}

TEST(Npy, ReadsVersion2And3Headers) {
  TempDir dir;
  const auto d = iota_values(6);
  for (int major : {2, 3}) {
    const fs::path p = dir / ("v" + std::to_string(major) + ".npy");
    write_bytes(p, make_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (3, 2), }", le_bytes(d), major));
    const auto a = read_npy(p);
    EXPECT_EQ(a.shape, (std::vector<std::size_t>{3, 2})) << major;
    EXPECT_EQ(a.data, d) << major;
  }
}

TEST(Npy, HeaderSpellingVariants) {
  TempDir dir;
  const auto d = iota_values(6);
  const char* dicts[] = {
      "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }",  // NumPy's own
      "{'descr':'<f8','fortran_order':False,'shape':(2,3)}",          // no spaces, no trailing comma
      "{ 'shape' : ( 2 , 3 , ) , 'descr' : '<f8' , 'fortran_order' : False , }",  // spaces, trailing commas
      "{\"descr\": \"<f8\", \"fortran_order\": False, \"shape\": (2, 3)}",        // double quotes
      "{'descr': '<f8', 'fortran_order': False, 'shape': (2L, 3L), }",            // Python 2 longs
  };
  int n = 0;
  for (const char* dict : dicts) {
    const fs::path p = dir / ("h" + std::to_string(n++) + ".npy");
    write_bytes(p, make_npy(dict, le_bytes(d)));
    const auto a = read_npy(p);
    EXPECT_EQ(a.shape, (std::vector<std::size_t>{2, 3})) << dict;
    EXPECT_EQ(a.data, d) << dict;
  }
  // A trailing comma in a one-element shape.
  write_bytes(dir / "t.npy", make_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (6,), }", le_bytes(d)));
  EXPECT_EQ(read_npy(dir / "t.npy").shape, (std::vector<std::size_t>{6}));
  // Old NumPy padded to 16 bytes, not 64: the reader does not insist on either.
  std::string odd = "\x93NUMPY";
  odd += '\x01';
  odd += '\x00';
  const std::string h = "{'descr': '<f8', 'fortran_order': False, 'shape': (6,)}\n";
  odd += static_cast<char>(h.size());
  odd += '\0';
  write_bytes(dir / "odd.npy", odd + h + le_bytes(d));
  EXPECT_EQ(read_npy(dir / "odd.npy").data, d);
}

// --- Errors ---------------------------------------------------------------------

TEST(Npy, BadMagicIsMalformed) {
  TempDir dir;
  write_bytes(dir / "bad.npy", "PK\x03\x04 this is a zip file, not an npy file");
  EXPECT_ERRC((void)read_npy(dir / "bad.npy"), malformed_file, "bad.npy: not an NPY file (bad magic");
  write_bytes(dir / "short.npy", "\x93NUM");
  EXPECT_ERRC((void)read_npy(dir / "short.npy"), malformed_file, "short.npy: not an NPY file (4 bytes");
}

TEST(Npy, UnsupportedVersionIsMalformed) {
  TempDir dir;
  write_bytes(dir / "v4.npy", make_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), }", le_bytes(iota_values(1)), 4));
  EXPECT_ERRC((void)read_npy(dir / "v4.npy"), malformed_file, "NPY format version 4.0 is not supported");
}

TEST(Npy, BadHeaderIsMalformed) {
  TempDir dir;
  const std::string d = le_bytes(iota_values(2));
  struct Case {
    const char* dict;
    const char* fragment;
  };
  const Case cases[] = {
      {"{'descr': '<f8', 'shape': (2,), }", "key 'fortran_order' is missing"},
      {"{'fortran_order': False, 'shape': (2,), }", "key 'descr' is missing"},
      {"{'descr': '<f8', 'fortran_order': False, }", "key 'shape' is missing"},
      {"{'descr': '<f8', 'fortran_order': false, 'shape': (2,), }", "expected True or False"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': (2,), 'extra': 1}", "unexpected key 'extra'"},
      {"{'descr': '<f8', 'descr': '<f8', 'fortran_order': False, 'shape': (2,)}", "key 'descr' appears twice"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': (-2,), }", "expected a non-negative integer"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': [2], }", "expected '('"},
      {"{'descr': '<f8 , 'fortran_order': False, 'shape': (2,)", "malformed NPY header"},
      {"'descr': '<f8', 'fortran_order': False, 'shape': (2,)", "expected '{'"},
      {"{'descr': '<f8' 'fortran_order': False, 'shape': (2,)}", "expected ',' or '}'"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': (2,)} junk", "unexpected text after the closing '}'"},
  };
  int n = 0;
  for (const Case& c : cases) {
    const std::string name = "h" + std::to_string(n++) + ".npy";
    write_bytes(dir / name, make_npy(c.dict, d));
    EXPECT_ERRC((void)read_npy(dir / name), malformed_file, c.fragment);
    EXPECT_ERRC((void)read_npy(dir / name), malformed_file, name + ": malformed NPY header");
  }
}

TEST(Npy, HeaderLongerThanFileIsMalformed) {
  TempDir dir;
  std::string bytes = make_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), }", "");
  bytes.resize(40);
  write_bytes(dir / "cut.npy", bytes);
  EXPECT_ERRC((void)read_npy(dir / "cut.npy"), malformed_file, "cut.npy: truncated NPY header: declares 118 bytes");
}

TEST(Npy, UnsupportedDtypeIsMalformed) {
  TempDir dir;
  const std::string d = le_bytes(std::vector<std::int32_t>{1, 2, 3, 4});
  for (const char* dtype : {"<i4", "|f8", "<c16", "<f2", "|u1", "O", "<U3"}) {
    write_bytes(dir / "i.npy",
                make_npy(std::string("{'descr': '") + dtype + "', 'fortran_order': False, 'shape': (4,), }", d));
    EXPECT_ERRC((void)read_npy(dir / "i.npy"), malformed_file,
                std::string("i.npy: dtype '") + dtype + "' is not supported; use float64 or float32");
  }
  write_bytes(dir / "s.npy", make_npy("{'descr': [('x', '<f8'), ('y', '<f8')], 'fortran_order': False, 'shape': (1,), }",
                                      le_bytes(iota_values(2))));
  EXPECT_ERRC((void)read_npy(dir / "s.npy"), malformed_file, "structured dtype is not supported");
}

TEST(Npy, TruncatedDataNamesShapeAndSizes) {
  TempDir dir;
  write_bytes(dir / "file.npy", make_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (4, 5, 3), }",
                                         std::string(100, '\0')));
  EXPECT_ERRC((void)read_npy(dir / "file.npy"), malformed_file,
              "file.npy: truncated: shape (4, 5, 3) needs 480 bytes of data, found 100");
  write_bytes(dir / "f4.npy", make_npy("{'descr': '<f4', 'fortran_order': False, 'shape': (10,), }",
                                       std::string(39, '\0')));
  EXPECT_ERRC((void)read_npy(dir / "f4.npy"), malformed_file, "shape (10,) needs 40 bytes of data, found 39");
}

TEST(Npy, ExtraDataIsMalformed) {
  TempDir dir;
  write_bytes(dir / "x.npy", make_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }",
                                      le_bytes(iota_values(7))));
  EXPECT_ERRC((void)read_npy(dir / "x.npy"), malformed_file,
              "x.npy: 8 bytes of extra data: shape (2, 3) needs 48 bytes of data, found 56");
}

TEST(Npy, UnreadableFile) {
  TempDir dir;
  EXPECT_ERRC((void)read_npy(dir / "missing.npy"), file_unreadable, "missing.npy': No such file or directory");
  EXPECT_ERRC((void)read_npy(dir.path()), file_unreadable, "it is a directory");
  if (::geteuid() != 0) {  // root reads anything
    write_bytes(dir / "locked.npy", make_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), }",
                                             le_bytes(iota_values(1))));
    fs::permissions(dir / "locked.npy", fs::perms::none);
    EXPECT_ERRC((void)read_npy(dir / "locked.npy"), file_unreadable, "Permission denied");
  }
}

TEST(Npy, DeclaredShapeTooLargeIsRefusedBeforeAllocating) {
  TempDir dir;
  // 2.4 TB of doubles declared in a file of a few bytes: too_large, not a bad_alloc
  // and not "truncated".
  write_bytes(dir / "huge.npy", make_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (100000000000, 3), }",
                                         le_bytes(iota_values(3))));
  EXPECT_ERRC((void)read_npy(dir / "huge.npy"), too_large, "huge.npy: array of shape (100000000000, 3) needs 2.4 TB");
  // Element count overflows size_t.
  write_bytes(dir / "over.npy", make_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (4294967296, 4294967296, 3), }",
                                         le_bytes(iota_values(3))));
  EXPECT_ERRC((void)read_npy(dir / "over.npy"), too_large, "shape (4294967296, 4294967296, 3)");
  // A dimension beyond 64 bits.
  write_bytes(dir / "dim.npy", make_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (123456789012345678901234,), }",
                                        le_bytes(iota_values(3))));
  EXPECT_ERRC((void)read_npy(dir / "dim.npy"), too_large, "dimension 123456789012345678901234");
}

TEST(Npy, WriteSizeMismatch) {
  TempDir dir;
  const std::vector<std::size_t> shape = {2, 3};
  const auto d = iota_values(5);
  EXPECT_ERRC(write_npy(dir / "m.npy", shape, d), size_mismatch, "shape (2, 3) has 6 elements, data has 5");
  EXPECT_FALSE(fs::exists(dir / "m.npy"));
}

TEST(Npy, WriteToMissingDirectoryIsUnwritable) {
  TempDir dir;
  const std::vector<std::size_t> shape = {1};
  const std::vector<double> d = {1.0};
  EXPECT_ERRC(write_npy(dir / "nope" / "a.npy", shape, d), file_unwritable, "does not exist");
  EXPECT_FALSE(fs::exists(dir / "nope"));
}

TEST(Npy, FailedWriteKeepsTheOldFile) {
  TempDir dir;
  const std::vector<std::size_t> shape = {3};
  const std::vector<double> good = {1, 2, 3};
  write_npy(dir / "keep.npy", shape, good);
  const std::vector<double> bad = {1, 2};
  EXPECT_ERRC(write_npy(dir / "keep.npy", shape, bad), size_mismatch, "keep.npy");
  EXPECT_EQ(read_npy(dir / "keep.npy").data, good);
}

// --- Writing from a producer, block by block -------------------------------------------

// A producer of `data` that copies each block into memory of its own, reused from
// call to call, and records the calls.
struct RecordingProducer {
  std::span<const double> data;
  std::vector<std::pair<std::size_t, std::size_t>> calls;  // (first, count)
  std::vector<double> block;

  NpyProducer producer() {
    return [this](std::size_t first, std::size_t count) {
      calls.emplace_back(first, count);
      block.assign(data.begin() + static_cast<std::ptrdiff_t>(first),
                   data.begin() + static_cast<std::ptrdiff_t>(first + count));
      return std::span<const double>(block);
    };
  }
};

TEST(Npy, WriteFromAProducerGivesTheBytesOfWriteFromData) {
  TempDir dir;
  auto g = test::rng(14);
  struct Case {
    std::vector<std::size_t> shape;
    std::vector<std::size_t> blocks;
  };
  const std::size_t many = (std::size_t{3} << 20) / sizeof(double) + 5;  // more than the file writer's buffer
  const std::vector<Case> cases{
      {{4, 5, 3}, {1, 12, 60, 7, 11, 61, 1000, std::numeric_limits<std::size_t>::max()}},
      {{many}, {std::size_t{1} << 16, 65537, many - 1}},
      {{}, {1, 5}},      // a scalar: one value
      {{0, 3}, {1, 4}},  // empty: no value at all
      {{3, 0, 2}, {2}},
  };
  for (const Case& c : cases) {
    std::size_t count = 1;
    for (std::size_t d : c.shape) count *= d;
    std::vector<double> data(count);
    for (double& v : data) v = test::uniform(g, -1e3, 1e3);
    if (count >= 3) {
      data[0] = -0.0;
      data[1] = std::numeric_limits<double>::denorm_min();
      data[2] = std::numeric_limits<double>::max();
    }
    write_npy(dir / "whole.npy", c.shape, data);
    const std::string expected = read_bytes(dir / "whole.npy");
    for (const std::size_t block : c.blocks) {
      SCOPED_TRACE(std::to_string(count) + " values in blocks of " + std::to_string(block));
      RecordingProducer p{data, {}, {}};
      write_npy(dir / "blocks.npy", c.shape, block, p.producer());
      EXPECT_TRUE(read_bytes(dir / "blocks.npy") == expected);
      // Consecutive blocks from 0, each full but the last, covering every value once.
      std::size_t next = 0;
      for (const auto& [first, n] : p.calls) {
        EXPECT_EQ(first, next);
        EXPECT_EQ(n, std::min(block, count - first));
        EXPECT_GT(n, 0u);
        next = first + n;
      }
      EXPECT_EQ(next, count);
      EXPECT_EQ(p.calls.size(), count == 0 ? std::size_t{0} : (count - 1) / block + 1);
    }
  }
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"blocks.npy", "whole.npy"}));  // no temporary file left
}

TEST(Npy, WriteFromAProducerOfAWrongCountIsSizeMismatchAndKeepsTheOldFile) {
  TempDir dir;
  const std::vector<std::size_t> shape = {5, 6};
  const auto data = iota_values(30);
  write_npy(dir / "keep.npy", shape, iota_values(30, -1.5));
  const std::string old = read_bytes(dir / "keep.npy");
  for (const std::ptrdiff_t wrong : {-1, 1, -10}) {
    SCOPED_TRACE(wrong);
    std::vector<double> block;
    const NpyProducer produce = [&](std::size_t first, std::size_t count) {
      const std::size_t n = first == 10 ? static_cast<std::size_t>(static_cast<std::ptrdiff_t>(count) + wrong) : count;
      const auto from = data.begin() + static_cast<std::ptrdiff_t>(first);
      block.assign(from, from + static_cast<std::ptrdiff_t>(n));
      return std::span<const double>(block);
    };
    EXPECT_ERRC(write_npy(dir / "keep.npy", shape, 10, produce), size_mismatch,
                "values 10 to 19 came as " + std::to_string(10 + wrong) + " values");
    EXPECT_TRUE(read_bytes(dir / "keep.npy") == old);
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.npy"});
  }
}

// The exception of a caller's producer or row maker.
struct producer_failed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// keep.npy in `dir`, a file a failed write must leave as it is: its bytes.
std::string kept_file(const TempDir& dir, const std::vector<std::size_t>& shape) {
  write_npy(dir / "keep.npy", shape, iota_values(shape[0] * shape[1]));
  return read_bytes(dir / "keep.npy");
}

TEST(Npy, WriteFromAProducerThatThrowsPassesItOnAndKeepsTheOldFile) {
  TempDir dir;
  const std::vector<std::size_t> shape = {1000, 3};
  const std::string old = kept_file(dir, shape);
  std::vector<double> block;
  const auto failing_at = [&](std::size_t at, auto failure) {
    return NpyProducer([&block, at, failure](std::size_t first, std::size_t count) {
      if (first == at) throw failure;
      block.assign(count, 1.0);
      return std::span<const double>(block);
    });
  };
  try {
    write_npy(dir / "keep.npy", shape, 512, failing_at(2048, producer_failed("block 4 failed")));
    ADD_FAILURE() << "expected the producer's exception";
  } catch (const producer_failed& e) {
    EXPECT_STREQ(e.what(), "block 4 failed");
  }
  EXPECT_TRUE(read_bytes(dir / "keep.npy") == old);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.npy"});
  // The library's own errors pass unchanged too, from the first block as from a later one.
  for (const std::size_t at : {std::size_t{0}, std::size_t{2560}}) {
    EXPECT_ERRC(write_npy(dir / "keep.npy", shape, 512, failing_at(at, error(errc::not_finite, "point 7 is nan"))),
                not_finite, "point 7 is nan");
    EXPECT_TRUE(read_bytes(dir / "keep.npy") == old);
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.npy"});
  }
  // A new file is not created.
  EXPECT_THROW(write_npy(dir / "new.npy", shape, 512, failing_at(0, producer_failed("no"))), producer_failed);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.npy"});
}

TEST(Npy, WriteFromAProducerInBlocksOfNothingIsSizeMismatch) {
  TempDir dir;
  const std::vector<std::size_t> shape = {4};
  write_npy(dir / "keep.npy", shape, iota_values(4));
  const std::string old = read_bytes(dir / "keep.npy");
  bool called = false;
  const NpyProducer produce = [&](std::size_t, std::size_t) {
    called = true;
    return std::span<const double>();
  };
  EXPECT_ERRC(write_npy(dir / "keep.npy", shape, 0, produce), size_mismatch, "blocks of 0 values");
  EXPECT_ERRC(write_npy(dir / "new.npy", shape, 0, produce), size_mismatch, "new.npy");
  EXPECT_FALSE(called);
  EXPECT_TRUE(read_bytes(dir / "keep.npy") == old);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.npy"});
}

// --- Rows made on every thread while the block before is written ---------------------

// write_npy_rows gives the bytes of write_npy, every row made once, on 1, 2 and 3
// threads: many blocks of small rows, rows larger than a block (two a block), one
// row, no row, a single axis.
TEST(Npy, WriteByRowsGivesTheBytesOfWriteFromData) {
  TempDir dir;
  auto g = test::rng(15);
  const std::vector<std::vector<std::size_t>> shapes{{5000, 7, 3}, {5, 100003}, {1, 4}, {0, 3}, {70001}};
#ifdef _OPENMP
  const int before = omp_get_max_threads();
  omp_set_dynamic(0);
#endif
  for (const auto& shape : shapes) {
    std::size_t count = 1;
    for (std::size_t d : shape) count *= d;
    const std::size_t per_row = shape[0] == 0 ? 0 : count / shape[0];
    std::vector<double> data(count);
    for (double& v : data) v = test::uniform(g, -1e3, 1e3);
    write_npy(dir / "whole.npy", shape, data);
    const std::string expected = read_bytes(dir / "whole.npy");
    for (const int threads : {1, 2, 3}) {
#ifdef _OPENMP
      omp_set_num_threads(threads);
#endif
      SCOPED_TRACE(std::to_string(count) + " values, " + std::to_string(threads) + " threads");
      std::vector<std::atomic<int>> made(shape[0]);
      write_npy_rows(dir / "rows.npy", shape, [&](std::size_t first, std::size_t n, std::span<double> out) {
        ASSERT_EQ(out.size(), n * per_row);
        for (std::size_t r = first; r < first + n; ++r) made[r].fetch_add(1);
        std::copy_n(data.begin() + static_cast<std::ptrdiff_t>(first * per_row), n * per_row, out.begin());
      });
      EXPECT_TRUE(read_bytes(dir / "rows.npy") == expected);
      EXPECT_TRUE(std::all_of(made.begin(), made.end(), [](const std::atomic<int>& m) { return m.load() == 1; }));
    }
  }
#ifdef _OPENMP
  omp_set_num_threads(before);
#endif
  // Two blocks held: of 2^17 values each, or of 2 rows when a row is larger.
  EXPECT_EQ(write_npy_rows_held(1000, 3000), 2 * 43 * 3000u);
  EXPECT_EQ(write_npy_rows_held(5, 100003), 2 * 2 * 100003u);
  EXPECT_EQ(write_npy_rows_held(1, 4), 2 * 1 * 4u);
  EXPECT_EQ(write_npy_rows_held(0, 3), 0u);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"rows.npy", "whole.npy"}));
}

// A row maker that throws: its exception passes on unchanged, the one for the first
// rows when rows in several blocks fail on several threads at once (the one a run on
// one thread meets), and the old file stays; a shape of no axis is size_mismatch.
TEST(Npy, WriteByRowsThatThrowsPassesOnTheFirstRowsFailureAndKeepsTheOldFile) {
  TempDir dir;
  const std::vector<std::size_t> shape = {20000, 3};
  const std::string old = kept_file(dir, shape);
  for (const std::size_t from : {std::size_t{0}, std::size_t{9000}, std::size_t{19999}}) {
    SCOPED_TRACE(from);
    try {
      write_npy_rows(dir / "keep.npy", shape, [&](std::size_t first, std::size_t n, std::span<double> out) {
        std::fill(out.begin(), out.end(), 1.0);
        if (first + n > from) throw producer_failed("rows from " + std::to_string(std::max(first, from)));
      });
      ADD_FAILURE() << "expected the maker's exception";
    } catch (const producer_failed& e) {
      EXPECT_EQ(std::string(e.what()), "rows from " + std::to_string(from));
    }
    EXPECT_TRUE(read_bytes(dir / "keep.npy") == old);
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.npy"});
  }
  EXPECT_ERRC(write_npy_rows(dir / "new.npy", shape,
                             [](std::size_t, std::size_t, std::span<double>) { throw error(errc::out_of_domain, "u = 2"); }),
              out_of_domain, "u = 2");
  EXPECT_ERRC(write_npy_rows(dir / "new.npy", std::vector<std::size_t>{}, [](std::size_t, std::size_t, std::span<double>) {}),
              size_mismatch, "cannot write '" + (dir / "new.npy").string() + "' by rows: the shape has no axis");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.npy"});
}

}  // namespace
}  // namespace interpatch::io
