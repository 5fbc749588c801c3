#include "interpatch/io/npz.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "interpatch/io/json_out.hpp"
#include "interpatch/io/npy.hpp"
#include "io/crc32.hpp"
#include "io/npz_internal.hpp"
#include "cli_specs.hpp"
#include "io/closed_shapes.hpp"
#include "npy_util.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch::io {
namespace {

namespace fs = std::filesystem;
using test::bilinear_members;
using test::bilinear_npz_with;
using test::crc32_bitwise;
using test::f8;
using test::le_bytes;
using test::npy_bytes;
using test::TempDir;
using test::zip_archive;
using test::ZipMember;

std::string read_bytes(const fs::path& p) { return test::read_text(p); }
using test::write_bytes;

std::uint64_t get_le(const std::string& s, std::size_t at, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes; i-- > 0;) v = (v << 8) | static_cast<unsigned char>(s[at + static_cast<std::size_t>(i)]);
  return v;
}

// --- CRC-32 ------------------------------------------------------------------------

TEST(Crc32, KnownValues) {
  EXPECT_EQ(internal::crc32("123456789", 9), 0xCBF43926u);
  EXPECT_EQ(internal::crc32("", 0), 0u);
  EXPECT_EQ(internal::crc32("a", 1), 0xE8B7BE43u);
  const std::string fox = "The quick brown fox jumps over the lazy dog";
  EXPECT_EQ(internal::crc32(fox.data(), fox.size()), 0x414FA339u);
  const std::string zeros(32, '\0');
  EXPECT_EQ(internal::crc32(zeros.data(), zeros.size()), 0x190A55ADu);
  std::string bytes;
  for (int r = 0; r < 3; ++r)
    for (int b = 0; b < 256; ++b) bytes += static_cast<char>(b);
  EXPECT_EQ(internal::crc32(bytes.data(), bytes.size()), 0xB0C0DF2Au);  // Python's zlib.crc32
}

std::string random_bytes(std::size_t n, unsigned seed) {
  auto g = test::rng(seed);
  std::string s(n, '\0');
  for (char& c : s) c = static_cast<char>(g() & 0xff);
  return s;
}

TEST(Crc32, AgreesWithTheDefinitionAtEveryLengthAndAlignment) {
  const std::string s = random_bytes(200, 1);
  for (std::size_t off = 0; off < 16; ++off)
    for (std::size_t len = 0; off + len <= 120; ++len)
      ASSERT_EQ(internal::crc32_serial(s.data() + off, len), crc32_bitwise(s.substr(off, len))) << off << " " << len;
}

TEST(Crc32, PiecesCombineIntoTheWhole) {
  // 12 MiB: the parallel path, whose pieces are combined.
  const std::string s = random_bytes((std::size_t{12} << 20) + 13, 2);
  const std::uint32_t whole = internal::crc32_serial(s.data(), s.size());
  EXPECT_EQ(internal::crc32(s.data(), s.size()), whole);
  auto g = test::rng(3);
  for (int k = 0; k < 20; ++k) {
    const std::size_t cut = g() % s.size();
    const std::uint32_t a = internal::crc32_serial(s.data(), cut), b = internal::crc32_serial(s.data() + cut, s.size() - cut);
    EXPECT_EQ(internal::crc32_combine(a, b, s.size() - cut), whole) << cut;
    EXPECT_EQ(internal::crc32_serial(s.data() + cut, s.size() - cut, a), whole) << cut;  // continued
  }
  EXPECT_EQ(internal::crc32_combine(0x12345678u, 0, 0), 0x12345678u);
  EXPECT_EQ(internal::crc32(s.data(), 1000), crc32_bitwise(s.substr(0, 1000)));
}

// --- Random exact forms -------------------------------------------------------------

// A clamped knot vector of `count` basis functions over [a, b], its interior knots
// random, some repeated (up to the degree).
KnotVector random_knots(std::mt19937_64& g, int p, std::size_t count, double a, double b) {
  std::vector<double> interior;
  const std::size_t n = count - static_cast<std::size_t>(p) - 1;
  while (interior.size() < n) {
    const double t = test::uniform(g, a + 0.01 * (b - a), b - 0.01 * (b - a));
    const std::size_t mult = std::min<std::size_t>(1 + g() % static_cast<std::size_t>(p), n - interior.size());
    interior.insert(interior.end(), mult, t);
  }
  std::sort(interior.begin(), interior.end());
  std::vector<double> k(static_cast<std::size_t>(p) + 1, a);
  k.insert(k.end(), interior.begin(), interior.end());
  k.insert(k.end(), static_cast<std::size_t>(p) + 1, b);
  return KnotVector(p, std::move(k));
}

// Values that text and careless binary formats mangle.
double random_value(std::mt19937_64& g) {
  static const double special[] = {-0.0, 5e-324, -2.2250738585072014e-308, 1.7976931348623157e308, 0.1, 1.0 / 3};
  if (g() % 8 == 0) return special[g() % std::size(special)];
  return test::uniform(g, -1e3, 1e3);
}

template <std::size_t D>
std::vector<KnotVector> random_knot_vectors(std::mt19937_64& g, std::array<std::size_t, D>& counts) {
  std::vector<KnotVector> k;
  const bool unit = g() % 2 == 0;  // over [0, 1], as build writes, or elsewhere
  for (std::size_t a = 0; a < D; ++a) {
    const int p = 1 + static_cast<int>(g() % 5);
    counts[a] = static_cast<std::size_t>(p) + 1 + g() % (D == 2 ? 12 : 5);
    k.push_back(random_knots(g, p, counts[a], unit ? 0.0 : -2.5, unit ? 1.0 : 7.25));
  }
  return k;
}

BSplineSurface random_surface(unsigned seed, bool rational) {
  auto g = test::rng(seed);
  std::array<std::size_t, 2> n{};
  std::vector<KnotVector> k = random_knot_vectors<2>(g, n);
  PointGrid cp({n[0], n[1]});
  for (Vec3& p : cp.values()) p = {random_value(g), random_value(g), random_value(g)};
  Grid<double, 2> w;
  if (rational) {
    w = Grid<double, 2>({n[0], n[1]});
    for (double& x : w.values()) x = test::uniform(g, 0.1, 3.0);
  }
  return BSplineSurface(std::move(k[0]), std::move(k[1]), std::move(cp), std::move(w));
}

BSplineVolume random_volume(unsigned seed, bool rational) {
  auto g = test::rng(seed);
  std::array<std::size_t, 3> n{};
  std::vector<KnotVector> k = random_knot_vectors<3>(g, n);
  PointGrid3 cp({n[0], n[1], n[2]});
  for (Vec3& p : cp.values()) p = {random_value(g), random_value(g), random_value(g)};
  Grid<double, 3> w;
  if (rational) {
    w = Grid<double, 3>({n[0], n[1], n[2]});
    for (double& x : w.values()) x = test::uniform(g, 0.1, 3.0);
  }
  return BSplineVolume(std::move(k[0]), std::move(k[1]), std::move(k[2]), std::move(cp), std::move(w));
}

bool same_bits(const double* a, std::size_t na, const double* b, std::size_t nb) {
  return na == nb && (na == 0 || std::memcmp(a, b, na * sizeof(double)) == 0);
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return same_bits(a.data(), a.size(), b.data(), b.size());
}

std::vector<const KnotVector*> knots_of(const BSplineSurface& s) { return {&s.knots_u(), &s.knots_v()}; }
std::vector<const KnotVector*> knots_of(const BSplineVolume& v) { return {&v.knots_u(), &v.knots_v(), &v.knots_w()}; }

// Degrees, knots, control points and weights, bit for bit.
template <class Form>
void expect_identical(const Form& a, const Form& b) {
  const auto ka = knots_of(a), kb = knots_of(b);
  for (std::size_t d = 0; d < ka.size(); ++d) {
    EXPECT_EQ(ka[d]->degree(), kb[d]->degree()) << "direction " << d;
    EXPECT_TRUE(same_bits(ka[d]->values(), kb[d]->values())) << "knots of direction " << d;
  }
  EXPECT_EQ(a.control_points().shape(), b.control_points().shape());
  EXPECT_TRUE(same_bits(&a.control_points().data()->x, 3 * a.control_points().size(), &b.control_points().data()->x,
                        3 * b.control_points().size()));
  EXPECT_EQ(a.rational(), b.rational());
  EXPECT_EQ(a.weights().shape(), b.weights().shape());
  EXPECT_TRUE(same_bits(a.weights().data(), a.weights().size(), b.weights().data(), b.weights().size()));
}

void expect_identical(const ExactForm& a, const ExactForm& b) {
  ASSERT_EQ(a.index(), b.index());
  if (a.index() == 0) expect_identical(std::get<BSplineSurface>(a), std::get<BSplineSurface>(b));
  else expect_identical(std::get<BSplineVolume>(a), std::get<BSplineVolume>(b));
}

// --- Round trips --------------------------------------------------------------------

TEST(Npz, SurfacesAndVolumesRoundTripBitIdentically) {
  TempDir dir;
  for (unsigned seed = 0; seed < 40; ++seed) {
    SCOPED_TRACE(seed);
    const ExactForm f = seed < 24 ? ExactForm(random_surface(seed, seed % 2 == 1)) : ExactForm(random_volume(seed, seed % 2 == 0));
    write_exact_npz(dir / "f.npz", f);
    expect_identical(read_exact_npz(dir / "f.npz"), f);
    expect_identical(parse_exact_npz(read_bytes(dir / "f.npz"), "f.npz"), f);
  }
}

TEST(Npz, LargeNetRoundTripsThroughTheParallelPaths) {
  // 600 x 700 control points, 10 MB: the blocked, checksummed writes and the
  // parallel pieces of the read (with their checksums combined).
  TempDir dir;
  PointGrid cp({600, 700});
  auto g = test::rng(7);
  for (Vec3& p : cp.values()) p = test::random_point(g, 100);
  Grid<double, 2> w({600, 700});
  for (double& x : w.values()) x = test::uniform(g, 0.5, 2);
  const ExactForm s = BSplineSurface(KnotVector::uniform(3, 600), KnotVector::uniform(2, 700), cp, w);
  write_exact_npz(dir / "big.npz", s);
  expect_identical(read_exact_npz(dir / "big.npz"), s);
  // A damaged byte deep in the control points is found by the checksum of the pieces.
  std::string bytes = read_bytes(dir / "big.npz");
  bytes[bytes.size() / 2] ^= 0x10;
  write_bytes(dir / "bad.npz", bytes);
  EXPECT_ERRC((void)read_exact_npz(dir / "bad.npz"), malformed_file, "control_points.npy: CRC-32 of its 10080128 bytes is");
}

TEST(Npz, Zip64RecordsRoundTrip) {
  TempDir dir;
  const ExactForm s = random_surface(5, true), v = random_volume(6, false);
  for (const ExactForm* f : {&s, &v}) {
    internal::write_exact_npz(dir / "z.npz", *f, true);
    expect_identical(read_exact_npz(dir / "z.npz"), *f);
    const std::string bytes = read_bytes(dir / "z.npz");
    // The end record's fields all point to the ZIP64 end record before its locator.
    const std::size_t end = bytes.size() - 22;
    EXPECT_EQ(get_le(bytes, end, 4), 0x06054b50u);
    EXPECT_EQ(get_le(bytes, end + 12, 4), 0xFFFFFFFFu);
    EXPECT_EQ(get_le(bytes, end + 16, 4), 0xFFFFFFFFu);
    EXPECT_EQ(get_le(bytes, end - 20, 4), 0x07064b50u);
    EXPECT_EQ(get_le(bytes, end - 20 - 56, 4), 0x06064b50u);
  }
}

// The members in file order, walking the local headers from the start of the file:
// the names, and the checksums the local headers record (filled in after the data).
struct LocalMember {
  std::string name;
  std::string data;
  std::uint32_t crc;
};

std::vector<LocalMember> local_members(const std::string& zip) {
  std::vector<LocalMember> out;
  std::size_t at = 0;
  while (get_le(zip, at, 4) == 0x04034b50u) {
    EXPECT_EQ(get_le(zip, at + 8, 2), 0u) << "stored";
    const std::size_t name_len = get_le(zip, at + 26, 2), extra_len = get_le(zip, at + 28, 2);
    std::uint64_t size = get_le(zip, at + 18, 4);
    if (size == 0xFFFFFFFFu) size = get_le(zip, at + 30 + name_len + 4 + 8, 8);  // the compressed size in ZIP64
    const std::size_t data = at + 30 + name_len + extra_len;
    out.push_back({zip.substr(at + 30, name_len), zip.substr(data, size), static_cast<std::uint32_t>(get_le(zip, at + 14, 4))});
    at = data + size;
  }
  return out;
}

TEST(Npz, MembersAreStoredNpyFilesInOrderWithTheirChecksums) {
  TempDir dir;
  for (const bool zip64 : {false, true}) {
    const ExactForm v = random_volume(9, true);
    internal::write_exact_npz(dir / "v.npz", v, zip64);
    const std::vector<LocalMember> m = local_members(read_bytes(dir / "v.npz"));
    std::vector<std::string> names;
    for (const LocalMember& e : m) {
      names.push_back(e.name);
      EXPECT_EQ(e.crc, crc32_bitwise(e.data)) << e.name;
    }
    EXPECT_EQ(names, (std::vector<std::string>{"degree.npy", "knots_u.npy", "knots_v.npy", "knots_w.npy",
                                               "control_points.npy", "weights.npy", "periodic.npy"}));
    const auto& vol = std::get<BSplineVolume>(v);
    EXPECT_EQ(m[0].data.substr(m[0].data.size() - 24), le_bytes<std::int64_t>({vol.degree_u(), vol.degree_v(), vol.degree_w()}));
    EXPECT_NE(m[0].data.find("'descr': '<i8'"), std::string::npos);
    EXPECT_NE(m[4].data.find("'shape': (" + std::to_string(vol.control_points().extent(0)) + ", "), std::string::npos);
    EXPECT_NE(m[6].data.find("'descr': '|b1'"), std::string::npos);
    EXPECT_EQ(m[6].data.substr(m[6].data.size() - 3), std::string(3, '\0'));  // periodic: all False
    const NpyArray cp = parse_npy(m[4].data, "control_points.npy");
    EXPECT_EQ(cp.shape, (std::vector<std::size_t>{vol.control_points().extent(0), vol.control_points().extent(1),
                                                  vol.control_points().extent(2), 3}));
  }
}

// Closed forms: a pipe (closed around v, odd and even degrees), a tube's wall as a
// volume, a surface closed around u and v; and forms made by hand about a torus
// (closed_shapes.hpp): uneven and doubled periodic knots, weights, a domain other
// than [0, 1], a volume closed in every direction.
std::vector<ExactForm> closed_forms() {
  std::vector<ExactForm> f;
  for (const int q : {2, 3}) {
    nlohmann::json s = test::pipe_spec(6, 9, true);
    s["degree"] = {3, q};
    f.push_back(*build(s).exact);
  }
  nlohmann::json both = test::pipe_spec(5, 7, false);
  both["periodic"] = {true, true};
  f.push_back(*build(both).exact);
  f.push_back(*build(test::tube_spec(3, 7, 4, true)).exact);
  f.push_back(test::closed_surface({true, false}, 1, true));
  f.push_back(test::closed_surface({false, true}, 2));
  f.push_back(test::closed_surface({true, true}, 3, true));
  f.push_back(test::closed_volume({true, true}, 4));
  f.push_back(test::volume_closed_everywhere());
  return f;
}

// The form a spec of it builds: its knots mapped onto [0, 1] when they are not.
ExactForm on_unit_domain(const ExactForm& f) {
  if (const auto* s = std::get_if<BSplineSurface>(&f)) {
    const auto d = s->domain();
    return d[0] == std::pair{0.0, 1.0} && d[1] == std::pair{0.0, 1.0} ? f : ExactForm(s->mapped(0, 1, 0, 1));
  }
  const auto& v = std::get<BSplineVolume>(f);
  const auto d = v.domain();
  const bool unit = std::all_of(d.begin(), d.end(), [](const auto& x) { return x == std::pair{0.0, 1.0}; });
  return unit ? f : ExactForm(v.mapped(0, 1, 0, 1, 0, 1));
}

TEST(Npz, ClosedFormsRoundTripBitIdentically) {
  TempDir dir;
  for (const ExactForm& f : closed_forms()) {
    write_exact_npz(dir / "f.npz", f);
    const ExactForm back = read_exact_npz(dir / "f.npz");
    expect_identical(back, f);
    // The periodic member says which directions are closed.
    const std::vector<LocalMember> m = local_members(read_bytes(dir / "f.npz"));
    const std::string flags = m.back().data.substr(m.back().data.size() - (f.index() == 0 ? 2 : 3));
    std::string expected;
    if (const auto* s = std::get_if<BSplineSurface>(&f))
      for (const bool p : s->periodic()) expected += p ? '\1' : '\0';
    else
      for (const bool p : std::get<BSplineVolume>(f).periodic()) expected += p ? '\1' : '\0';
    EXPECT_EQ(m.back().name, "periodic.npy");
    EXPECT_EQ(flags, expected);
    // The .json exact form reads back to the same form, over [0, 1] as every spec's.
    std::ostringstream text;
    write_exact_json(text, f);
    expect_identical(*build(parse_json(text.str())).exact, on_unit_domain(back));
  }
}

TEST(Npz, TheSameFormGivesTheSameBytes) {
  TempDir dir;
  const ExactForm s = random_surface(12, true);
  write_exact_npz(dir / "a.npz", s);
  write_exact_npz(dir / "b.npz", s);
  EXPECT_EQ(read_bytes(dir / "a.npz"), read_bytes(dir / "b.npz"));
}

TEST(Npz, ReadsArchivesItDidNotWrite) {
  // numpy.savez's layout: no periodic member, degrees as int32, knots as float32,
  // control points big endian in Fortran order.
  std::vector<ZipMember> m = bilinear_members();
  m.pop_back();
  m[0].data = npy_bytes("<i4", "(2,)", le_bytes<std::int32_t>({1, 1}));
  m[1].data = npy_bytes("<f4", "(4,)", le_bytes<float>({0, 0, 1, 1}));
  // Fortran order, the first index fastest: x of P00 P10 P01 P11, then y, then z.
  std::string be = f8({0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 0, 1});
  for (std::size_t i = 0; i < be.size(); i += 8) std::reverse(be.begin() + static_cast<long>(i), be.begin() + static_cast<long>(i + 8));
  m[3].data = test::make_npy("{'descr': '>f8', 'fortran_order': True, 'shape': (2, 2, 3), }", be);
  const auto s = std::get<BSplineSurface>(parse_exact_npz(zip_archive(m), "numpy.npz"));
  EXPECT_EQ(s.degree_u(), 1);
  EXPECT_EQ(s.knots_u().values(), (std::vector<double>{0, 0, 1, 1}));
  EXPECT_EQ(s.control_points()(1, 1), (Vec3{1, 1, 1}));
  EXPECT_EQ(s.control_points()(0, 1), (Vec3{0, 1, 0}));
  EXPECT_FALSE(s.rational());
}

TEST(Npz, FailedWritesLeaveNothing) {
  TempDir dir;
  EXPECT_ERRC(write_exact_npz(dir / "missing" / "s.npz", random_surface(1, false)), file_unwritable, "does not exist");
  EXPECT_TRUE(dir.entries().empty());
}

TEST(Npz, MissingOrUnreadableFiles) {
  TempDir dir;
  EXPECT_ERRC((void)read_exact_npz(dir / "nope.npz"), file_unreadable, "cannot open '" + (dir / "nope.npz").string() + "'");
  fs::create_directory(dir / "d.npz");
  EXPECT_ERRC((void)read_exact_npz(dir / "d.npz"), file_unreadable, "it is a directory");
}

// --- Damaged archives ---------------------------------------------------------------

// A small rational surface's archive, every member present.
std::string small_archive() {
  TempDir dir;
  write_exact_npz(dir / "s.npz", random_surface(3, true));
  return read_bytes(dir / "s.npz");
}

TEST(NpzMalformed, TruncatedAnywhereIsAMalformedFileNamed) {
  const std::string bytes = small_archive();
  for (std::size_t cut = 0; cut < bytes.size(); ++cut) {
    try {
      (void)parse_exact_npz(std::string_view(bytes).substr(0, cut), "cut.npz");
      ADD_FAILURE() << "accepted the first " << cut << " of " << bytes.size() << " bytes";
    } catch (const error& e) {
      ASSERT_EQ(e.code(), errc::malformed_file) << cut << ": " << e.what();
      ASSERT_EQ(std::string(e.what()).rfind("cut.npz: ", 0), 0u) << e.what();
    }
  }
  // And as files, at some offsets.
  TempDir dir;
  for (std::size_t cut = 0; cut < bytes.size(); cut += 97) {
    write_bytes(dir / "t.npz", bytes.substr(0, cut));
    try {
      (void)read_exact_npz(dir / "t.npz");
      ADD_FAILURE() << "accepted " << cut << " bytes";
    } catch (const error& e) {
      EXPECT_TRUE(e.code() == errc::malformed_file || e.code() == errc::file_unreadable) << e.what();
      EXPECT_NE(std::string(e.what()).find((dir / "t.npz").string()), std::string::npos) << e.what();
    }
  }
}

TEST(NpzMalformed, EveryChangedByteIsFoundOrHarmless) {
  const std::string good = small_archive();
  const ExactForm original = parse_exact_npz(good, "good.npz");
  std::size_t found = 0, harmless = 0;
  for (std::size_t at = 0; at < good.size(); ++at)
    for (const int x : {0x01, 0x80, 0xff}) {
      std::string bad = good;
      bad[at] = static_cast<char>(bad[at] ^ x);
      try {
        const ExactForm f = parse_exact_npz(bad, "bad.npz");
        expect_identical(f, original);  // a field no reader uses (version made by, attributes, ...)
        ++harmless;
      } catch (const error& e) {
        ASSERT_NE(e.code(), errc::internal) << at << ": " << e.what();
        ASSERT_EQ(std::string(e.what()).rfind("bad.npz", 0), 0u) << at << ": " << e.what();
        ++found;
      }
    }
  // Every byte of every member is covered by its checksum: most changes are found.
  EXPECT_GT(found, 10 * harmless);
}

// One hand-made archive each, and what the reader says of it.
struct Case {
  const char* name;
  std::string bytes;
  errc code;
  const char* pattern;  // regex searched in the message
};

std::string replace_bytes(std::string s, std::size_t at, std::uint64_t v, int n) {
  for (int i = 0; i < n; ++i, v >>= 8) s[at + static_cast<std::size_t>(i)] = static_cast<char>(v & 0xff);
  return s;
}

std::vector<Case> cases() {
  using test::bilinear_npz_with;
  const std::string good = zip_archive(bilinear_members());
  const std::size_t end = good.size() - 22;
  const std::size_t dir = get_le(good, end + 16, 4);
  std::vector<ZipMember> compressed = bilinear_members(), encrypted = bilinear_members(), crc = bilinear_members(),
                         extra = bilinear_members(), twice = bilinear_members(), weights = bilinear_members();
  compressed[3].method = 8;
  encrypted[2].flags = 1;
  crc[3].crc = 0x1234;
  extra.push_back({"weight.npy", npy_bytes("<f8", "(2, 2)", f8({1, 1, 1, 1}))});
  twice.push_back(twice[1]);
  std::string renamed = good;
  renamed[30 + 2] = 'X';  // the first local header's name: deXree.npy
  const auto with_weights = [&](const std::string& shape, const std::vector<double>& w) {
    std::vector<ZipMember> m = bilinear_members();
    m.push_back({"weights.npy", npy_bytes("<f8", shape, f8(w))});
    return zip_archive(m);
  };
  const std::string cp = "control_points.npy";
  const std::vector<double> four{0, 0, 1, 1};
  return {
      {"Empty", "", errc::malformed_file, R"(^x\.npz: not an \.npz archive \(0 bytes, shorter than the 22-byte end record)"},
      {"NotAZip", "hello, world, this is text", errc::malformed_file, R"(^x\.npz: not an \.npz archive: no ZIP end-of-central-directory record in its last 26 of 26 bytes)"},
      {"AnNpy", npy_bytes("<f8", "(2,)", f8({1, 2})), errc::malformed_file, R"(^x\.npz: a single \.npy array, not an \.npz archive)"},
      {"Truncated", good.substr(0, good.size() - 5), errc::malformed_file, R"(^x\.npz: truncated ZIP archive: no end-of-central-directory record)"},
      {"Compressed", zip_archive(compressed), errc::malformed_file,
       R"(^x\.npz: member 'control_points\.npy' is compressed \(method 8, deflate\); only stored members are read)"},
      {"Encrypted", zip_archive(encrypted), errc::malformed_file, R"(^x\.npz: member 'knots_v\.npy' is encrypted)"},
      {"CrcMismatch", zip_archive(crc), errc::malformed_file,
       R"(^x\.npz: control_points\.npy: CRC-32 of its 224 bytes is 0x[0-9a-f]{8}, the archive records 0x00001234: the file is damaged)"},
      {"MissingKnots", bilinear_npz_with("knots_v.npy", ""), errc::malformed_file,
       R"(^x\.npz: no member 'knots_v\.npy' \(an exact form holds degree, knots_u, .*; this archive holds degree\.npy, knots_u\.npy, control_points\.npy, periodic\.npy\))"},
      {"MissingDegree", bilinear_npz_with("degree.npy", ""), errc::malformed_file, R"(^x\.npz: no member 'degree\.npy')"},
      {"UnknownMember", zip_archive(extra), errc::malformed_file, R"(^x\.npz: member 'weight\.npy' is not an array of an exact form)"},
      {"MemberTwice", zip_archive(twice), errc::malformed_file, R"(^x\.npz: member 'knots_u\.npy' appears twice)"},
      {"LocalNameDiffers", renamed, errc::malformed_file, R"(^x\.npz: member 'degree\.npy': its local header names it 'deXree\.npy')"},
      {"BadLocalSignature", replace_bytes(good, 0, 0x04034b51, 4), errc::malformed_file,
       R"(^x\.npz: member 'degree\.npy': no local header at offset 0 \(bad signature\))"},
      {"MemberPastTheDirectory", replace_bytes(replace_bytes(good, dir + 20, 100000, 4), dir + 24, 100000, 4), errc::malformed_file,
       R"(^x\.npz: member 'degree\.npy' of 100000 bytes at offset 40 runs past the central directory at offset \d+ \(the file has \d+ bytes\))"},
      {"SizesDisagree", replace_bytes(good, dir + 20, 100, 4), errc::malformed_file,
       R"(^x\.npz: stored member 'degree\.npy' has 100 bytes in the archive but a size of 144)"},
      {"DirectoryPastTheEnd", replace_bytes(good, end + 16, dir + 1000, 4), errc::malformed_file,
       R"(^x\.npz: the central directory \(\d+ bytes at offset \d+\) runs past the end records)"},
      {"DirectoryDamaged", replace_bytes(good, dir, 0x02014b51, 4), errc::malformed_file,
       R"(^x\.npz: the central directory \(\d+ bytes\) ends or is damaged at its byte 0, in entry 1 of 5)"},
      {"Zip64Missing", replace_bytes(good, end + 10, 0xFFFF, 2), errc::malformed_file,
       R"(^x\.npz: the end record refers to a ZIP64 end record .* but there is none)"},
      {"SeveralDisks", replace_bytes(good, end + 4, 1, 2), errc::malformed_file, R"(^x\.npz: the archive spans several disks)"},
      {"NpyMemberTruncated", bilinear_npz_with(cp, npy_bytes("<f8", "(2, 2, 3)", f8({0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1}))), errc::malformed_file,
       R"(^x\.npz: control_points\.npy: truncated: shape \(2, 2, 3\) needs 96 bytes of data, found 88)"},
      {"NpyMemberNotNpy", bilinear_npz_with(cp, "not an npy"), errc::malformed_file,
       R"(^x\.npz: control_points\.npy: not an NPY file \(bad magic)"},
      {"FloatDegrees", bilinear_npz_with("degree.npy", npy_bytes("<f8", "(2,)", f8({1, 1}))), errc::wrong_type,
       R"(^x\.npz: degree\.npy: dtype '<f8'; expected integers \(int64\))"},
      {"IntegerControlPoints", bilinear_npz_with(cp, npy_bytes("<i8", "(2, 2, 3)", std::string(96, '\0'))), errc::wrong_type,
       R"(^x\.npz: control_points\.npy: dtype '<i8'; expected float64 \(or float32\))"},
      {"ComplexKnots", bilinear_npz_with("knots_u.npy", npy_bytes("<c16", "(4,)", std::string(64, '\0'))), errc::wrong_type,
       R"(^x\.npz: knots_u\.npy: dtype '<c16'; expected float64)"},
      {"IntegerPeriodic", bilinear_npz_with("periodic.npy", npy_bytes("<i8", "(2,)", std::string(16, '\0'))), errc::wrong_type,
       R"(^x\.npz: periodic\.npy: dtype '<i8'; expected bool)"},
      {"FourDegrees", bilinear_npz_with("degree.npy", npy_bytes("<i8", "(4,)", le_bytes<std::int64_t>({1, 1, 1, 1}))),
       errc::size_mismatch, R"(^x\.npz: degree\.npy has shape \(4,\); expected \(2,\) \(a surface\) or \(3,\) \(a volume\))"},
      {"DegreeZero", bilinear_npz_with("degree.npy", npy_bytes("<i8", "(2,)", le_bytes<std::int64_t>({1, 0}))),
       errc::invalid_degree, R"(^x\.npz: degree\.npy: degree 0 along v is outside 1\.\.30)"},
      {"DegreeHuge", bilinear_npz_with("degree.npy", npy_bytes("<i8", "(2,)", le_bytes<std::int64_t>({-5, 1}))),
       errc::invalid_degree, R"(^x\.npz: degree\.npy: degree -5 along u is outside 1\.\.30)"},
      {"ControlPointsNotTriples", bilinear_npz_with(cp, npy_bytes("<f8", "(2, 2)", f8({0, 0, 1, 1}))), errc::size_mismatch,
       R"(^x\.npz: control_points\.npy has shape \(2, 2\); expected \(n, m, 3\), the knots need \(2, 2, 3\))"},
      {"ControlPointsOfAnotherCount", bilinear_npz_with(cp, npy_bytes("<f8", "(2, 3, 3)", f8(std::vector<double>(18, 0.5)))),
       errc::size_mismatch,
       R"(^x\.npz: control_points\.npy has shape \(2, 3, 3\), but the 4 knots of degree 1 in knots_v\.npy need 2 control points along v, \(2, 2, 3\))"},
      {"NanControlPoint", bilinear_npz_with(cp, npy_bytes("<f8", "(2, 2, 3)", f8({0, 0, 0, 0, 1, 0, std::nan(""), 0, 0, 1, 1, 1}))),
       errc::not_finite, R"(^x\.npz: control_points\.npy: control point \[1\]\[0\] is \(nan, 0, 0\))"},
      {"WeightsOfAnotherShape", with_weights("(2, 3)", std::vector<double>(6, 1.0)), errc::size_mismatch,
       R"(^x\.npz: weights\.npy has shape \(2, 3\); the control points need one weight each, \(2, 2\))"},
      {"ZeroWeight", with_weights("(2, 2)", {1, 0, 1, 1}), errc::invalid_weight,
       R"(^x\.npz: weights\.npy: weight \[0\]\[1\] is 0; weights must be positive)"},
      {"InfiniteWeight", with_weights("(2, 2)", {1, 1, 1, HUGE_VAL}), errc::not_finite, R"(^x\.npz: weights\.npy: weight \[1\]\[1\] is inf)"},
      {"KnotsDecrease", bilinear_npz_with("knots_u.npy", npy_bytes("<f8", "(5,)", f8({0, 0, 0.7, 0.3, 1}))), errc::non_increasing,
       R"(^x\.npz: knots_u\.npy: knot 3 = 0\.3 is smaller than knot 2 = 0\.7)"},
      {"KnotsNotClamped", bilinear_npz_with("knots_v.npy", npy_bytes("<f8", "(4,)", f8({0, 0.5, 1, 1}))), errc::invalid_knots,
       R"(^x\.npz: knots_v\.npy: knot vector is not clamped at the start)"},
      {"NanKnot", bilinear_npz_with("knots_v.npy", npy_bytes("<f8", "(4,)", f8({0, 0, std::nan(""), 1}))), errc::not_finite,
       R"(^x\.npz: knots_v\.npy: knot 2 is nan)"},
      {"KnotsOfRankTwo", bilinear_npz_with("knots_u.npy", npy_bytes("<f8", "(2, 2)", f8(four))), errc::size_mismatch,
       R"(^x\.npz: knots_u\.npy has shape \(2, 2\); expected a 1-D array of knots)"},
      {"PeriodicWithClampedKnots", bilinear_npz_with("periodic.npy", npy_bytes("|b1", "(2,)", std::string("\0\1", 2))),
       errc::invalid_knots, R"(^x\.npz: knots_v\.npy: a periodic knot vector of degree 1 needs at least 5 extended knots)"},
      {"PeriodicOfThree", bilinear_npz_with("periodic.npy", npy_bytes("|b1", "(3,)", std::string(3, '\0'))), errc::size_mismatch,
       R"(^x\.npz: periodic\.npy has shape \(3,\); expected \(2,\), one entry per direction)"},
      {"KnotsWInASurface",
       [&] {
         std::vector<ZipMember> m = bilinear_members();
         m.push_back({"knots_w.npy", npy_bytes("<f8", "(4,)", f8(four))});
         return zip_archive(m);
       }(),
       errc::size_mismatch, R"(^x\.npz: knots_w\.npy is the third direction of a volume, but degree\.npy has shape \(2,\))"},
  };
}

TEST(NpzMalformed, EachErrorNamesTheFileTheMemberAndTheSize) {
  // The archive that every case changes one thing of is good.
  const auto s = std::get<BSplineSurface>(parse_exact_npz(zip_archive(bilinear_members()), "x.npz"));
  EXPECT_EQ(s.control_points()(1, 1), (Vec3{1, 1, 1}));
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    try {
      (void)parse_exact_npz(c.bytes, "x.npz");
      ADD_FAILURE() << "accepted";
    } catch (const error& e) {
      EXPECT_EQ(e.code(), c.code) << to_string(e.code()) << ": " << e.what();
      EXPECT_TRUE(std::regex_search(e.what(), std::regex(c.pattern))) << "'" << e.what() << "' does not match " << c.pattern;
    }
  }
}

TEST(NpzMalformed, AnArchiveOfTheOtherKind) {
  TempDir dir;
  write_exact_npz(dir / "v.npz", random_volume(4, false));
  EXPECT_ERRC((void)internal::read_exact_npz(dir / "v.npz", 2), wrong_type,
              (dir / "v.npz").string() + " holds a volume (degree.npy has shape (3,)); bspline_surface reads");
  write_exact_npz(dir / "s.npz", random_surface(4, false));
  EXPECT_ERRC((void)internal::read_exact_npz(dir / "s.npz", 3), wrong_type, " holds a surface (degree.npy has shape (2,))");
  expect_identical(internal::read_exact_npz(dir / "s.npz", 2), read_exact_npz(dir / "s.npz"));
}

// --- In a spec ----------------------------------------------------------------------

TEST(NpzSpec, ReadsBackTheFormBuildWrote) {
  TempDir dir;
  const Construction c = build(nlohmann::json::parse(test::read_text(fs::path(INTERPATCH_EXAMPLES) / "terrain.json")));
  write_exact_npz(dir / "t.npz", *c.exact);
  write_bytes(dir / "s.json", R"({"type": "bspline_surface", "npz": "t.npz"})");
  const Construction back = build_file(dir / "s.json");
  EXPECT_EQ(back.type, "bspline_surface");
  expect_identical(*back.exact, *c.exact);
  EXPECT_TRUE(back.warnings.empty());
  // The same for a volume, and a form over another domain mapped onto [0, 1] as
  // bspline_volume does with its fields.
  const BSplineVolume v = random_volume(21, true);
  write_exact_npz(dir / "v.npz", v);
  write_bytes(dir / "v.json", R"({"type": "bspline_volume", "npz": "v.npz"})");
  const Construction vb = build_file(dir / "v.json");
  const auto dom = v.domain();
  expect_identical(*vb.exact, dom[0] == std::pair{0.0, 1.0} ? ExactForm(v) : ExactForm(v.mapped(0, 1, 0, 1, 0, 1)));
  EXPECT_EQ(vb.parameters["domain"]["u"], nlohmann::ordered_json({dom[0].first, dom[0].second}));
}

TEST(NpzSpec, Errors) {
  TempDir dir;
  write_exact_npz(dir / "s.npz", random_surface(2, false));
  const auto spec = [&](const std::string& text) {
    write_bytes(dir / "x.json", text);
    return dir / "x.json";
  };
  EXPECT_ERRC((void)build_file(spec(R"({"type": "bspline_surface", "npz": "s.npz", "control_points": [[[0,0,0]]]})")), wrong_type,
              "/npz: give either \"npz\" or \"control_points\" (with the other fields of bspline_surface), not both");
  EXPECT_ERRC((void)build_file(spec(R"({"type": "bspline_volume", "npz": "s.npz", "degree": 2})")), wrong_type,
              "/npz: give either \"npz\" or \"degree\"");
  EXPECT_ERRC((void)build_file(spec(R"({"type": "bspline_surface", "npz": 3})")), wrong_type, "/npz: expected a file name");
  EXPECT_ERRC((void)build_file(spec(R"({"type": "bspline_surface", "npz": "none.npz"})")), file_unreadable,
              "/npz: cannot open '" + (dir / "none.npz").string() + "'");
  EXPECT_ERRC((void)build_file(spec(R"({"type": "bspline_volume", "npz": "s.npz"})")), wrong_type,
              "/npz: " + (dir / "s.npz").string() + " holds a surface");
  write_bytes(dir / "bad.npz", bilinear_npz_with("knots_v.npy", ""));
  EXPECT_ERRC((void)build_file(spec(R"({"type": "bspline_surface", "npz": "bad.npz"})")), malformed_file,
              "/npz: " + (dir / "bad.npz").string() + ": no member 'knots_v.npy'");
}

// --- For NumPy ----------------------------------------------------------------------

// Writes archives of random forms, with and without ZIP64 records, beside their .json
// exact forms, into $INTERPATCH_NPZ_SAMPLES: tools/check_npz.py then loads each with
// numpy.load and compares it with the .json (CTest runs the two in turn).
TEST(NpzForNumpy, WritesSamples) {
  const char* out = std::getenv("INTERPATCH_NPZ_SAMPLES");
  if (!out) GTEST_SKIP() << "INTERPATCH_NPZ_SAMPLES is not set (the CTest npz_numpy_zip64 sets it)";
  fs::create_directories(out);
  const std::vector<std::pair<std::string, ExactForm>> forms = {{"surface", random_surface(31, false)},
                                                                {"rational_surface", random_surface(32, true)},
                                                                {"volume", random_volume(33, false)},
                                                                {"rational_volume", random_volume(34, true)},
                                                                {"closed_surface", closed_forms()[1]},
                                                                {"closed_volume", closed_forms()[3]},
                                                                {"closed_rational_surface", closed_forms()[6]}};
  for (const auto& [name, form] : forms)
    for (const bool zip64 : {false, true}) {
      const std::string base = (fs::path(out) / (name + (zip64 ? "_zip64" : ""))).string();
      internal::write_exact_npz(base + ".npz", form, zip64);
      write_exact_json(base + ".json", form);
    }
}

}  // namespace
}  // namespace interpatch::io
