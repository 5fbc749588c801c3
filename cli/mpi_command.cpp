// eval and build of a grid interpolation split between MPI processes. Each process
// reads its block of rows of the .npy points (MPI-IO), the passes along the axes
// inside the rows run on the blocks (src/constructions/interpolate/grid_rows.hpp, the very functions
// the single process runs), one all-to-all turns the rows into columns for the
// solve along u and another turns the control points back into rows (with the
// halo each process's output rows need), and every process writes its part of the
// output in place; rank 0 renames the file into place when all have succeeded.

#include "mpi_command.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <limits>
#include <new>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "commands.hpp"
#include "constructions/approximate/approx_rows.hpp"
#include "constructions/interpolate/grid_rows.hpp"
#include "splines/row_window.hpp"
#include "exit_status.hpp"
#include "interpatch/error.hpp"
#include "interpatch/evaluate.hpp"
#include "interpatch/io/atomic_file.hpp"
#include "interpatch/memory.hpp"
#include "io/crc32.hpp"
#include "io/npy_format.hpp"
#include "io/npz_internal.hpp"
#include "io/spec/reader.hpp"
#include "mpi/team.hpp"

namespace interpatch::cli {

namespace fs = std::filesystem;
using detail::cat;
using detail::fail;

namespace {

// A peer's failure carries the status of the process that failed first.
int status_of(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const detail::peer_failure& p) {
    return p.status;
  } catch (...) {
    return exit_status(e);
  }
}

// What the split run needs to know before it reads a point; `split` false: the
// request runs on rank 0 alone.
struct Plan {
  bool split = false;
  std::size_t dims = 0;
  nlohmann::json spec;
  fs::path base, points;
  std::string file;  // as the spec names it
  std::vector<std::size_t> counts;  // --grid
  io::internal::NpyHeader header;
  io::internal::NpyDtype dtype;
  bool approximate = false;  // an approximate spec (dims 2), its options:
  SurfaceApproximationOptions approx;
};

Plan plan_of(const MpiRequest& r, const mpi::Team& team) {
  Plan plan;
  const Input in = parse_input(r.spec, r.shape);
  const fs::path out = r.out;
  if (r.build) check_build_output(out);
  else {
    plan.counts = parse_grid(r.grid);
    check_eval_output(out);
  }
  io::check_writable(out);
  std::string ext = out.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext != (r.build ? ".npz" : ".npy") || in.kind == Input::Kind::csv) return plan;
  plan.spec = in.kind == Input::Kind::npy ? data_file_spec(in) : io::read_json_file(in.path);
  plan.base = in.path.parent_path();
  const nlohmann::json& s = plan.spec;
  if (!s.is_object() || !s.contains("type") || !s["type"].is_string()) return plan;
  const std::string type = s["type"].get<std::string>();
  const bool approx = type == "approximate";
  plan.dims = type == "interpolate" || approx ? 2 : type == "interpolate_volume" ? 3 : 0;
  if (plan.dims == 0 || !s.contains("points") || !s["points"].is_object() || !s["points"].contains("npy")) return plan;
  io::reader::Context ctx;
  ctx.base_dir = plan.base;
  plan.file = io::reader::file_name(s["points"], "npy", "/points");
  plan.points = ctx.resolve(plan.file);
  // The header, read by every process; anything the split run does not read (other
  // dtypes, Fortran order, a shape that is not a grid, short data) is left to the
  // single process, which says what is wrong.
  std::string head;
  const std::uint64_t size = io::reader::at("/points", [&] {
    const mpi::InputFile file(plan.points, team);
    head.resize(static_cast<std::size_t>(std::min<std::uint64_t>(file.size(), 1 << 20)));
    file.read(head.data(), head.size(), 0);
    return file.size();
  });
  std::istringstream is(head);
  try {
    plan.header = io::internal::read_npy_header(is, size, plan.points.string());
  } catch (const error&) {
    return plan;
  }
  const auto dt = io::internal::parse_npy_dtype(plan.header.descr);
  const auto& shape = plan.header.shape;
  if (!dt || dt->kind != 'f' || shape.size() != plan.dims + 1 || shape.back() != 3)
    return plan;
  plan.dtype = *dt;
  std::uint64_t count = 1;
  for (const std::size_t e : shape) {
    if (e != 0 && count > (std::uint64_t{1} << 62) / e) return plan;
    count *= e;
  }
  if (count == 0 || plan.header.data_offset + count * dt->size != size) return plan;
  if (approx) {
    // Options the single process refuses run there.
    try {
      io::reader::Context fields;
      fields.base_dir = plan.base;
      (void)io::reader::check_fields(s, "", io::reader::find_type("approximate")->fields, fields);
      const std::vector<std::size_t> grid(shape.begin(), shape.begin() + 2);
      if (grid[0] < 2 || grid[1] < 2) return plan;
      plan.approx = io::reader::approximation_options<2>(s, "", grid, "/points");
    } catch (const error&) {
      return plan;
    }
    plan.approximate = true;
  }
  plan.split = true;
  return plan;
}

// One value of the file's dtype as a double (float32 widened, byte order swapped).
double file_value(const unsigned char* raw, const io::internal::NpyDtype& dtype) {
  const std::size_t es = dtype.size;
  unsigned char b[8];
  std::memcpy(b, raw, es);
  if (dtype.big_endian != (std::endian::native == std::endian::big)) std::reverse(b, b + es);
  if (es == 8) return std::bit_cast<double>(b);
  float f;
  std::memcpy(&f, b, 4);
  return static_cast<double>(f);
}

// Rows of the .npy file as doubles: rows [r, r + n) of `row` values each, C order.
void read_rows(const mpi::InputFile& file, const Plan& plan, std::size_t row, std::size_t r, std::size_t n, double* dst) {
  const std::size_t es = plan.dtype.size, total = row * n;
  if (n == 0) return;
  if (plan.header.fortran_order) {
    // Value q of a row (in the file's order: the first index after u fastest) is a
    // run of the n rows' values, n0 values apart from the next: a strided read of
    // the runs, then each value to its place in C order.
    const auto& shape = plan.header.shape;
    const std::size_t n0 = shape[0];
    const std::size_t group = std::max<std::size_t>(1, (std::size_t{1} << 20) / n);
    std::vector<unsigned char> raw(std::min(group, row) * n * es);
    for (std::size_t q0 = 0; q0 < row; q0 += group) {
      const std::size_t g = std::min(group, row - q0);
      file.read_strided(reinterpret_cast<char*>(raw.data()), g, n * es, std::uint64_t{n0} * es,
                        plan.header.data_offset + (std::uint64_t{r} + std::uint64_t{n0} * q0) * es);
      for (std::size_t q = q0; q < q0 + g; ++q) {
        std::size_t pos = 0, rest = q;  // q's place in a row in C order
        for (std::size_t a = 1; a < shape.size(); ++a) {
          std::size_t later = 1;
          for (std::size_t b = a + 1; b < shape.size(); ++b) later *= shape[b];
          pos += (rest % shape[a]) * later;
          rest /= shape[a];
        }
        for (std::size_t i = 0; i < n; ++i) dst[i * row + pos] = file_value(raw.data() + ((q - q0) * n + i) * es, plan.dtype);
      }
    }
    return;
  }
  const std::uint64_t at = plan.header.data_offset + std::uint64_t{r} * row * es;
  if (es == 8 && !plan.dtype.big_endian && std::endian::native == std::endian::little) {
    file.read(reinterpret_cast<char*>(dst), total * 8, at);
    return;
  }
  constexpr std::size_t piece = std::size_t{1} << 20;
  std::vector<unsigned char> raw(std::min(total, piece) * es);
  for (std::size_t done = 0; done < total; done += piece) {
    const std::size_t k = std::min(piece, total - done);
    file.read(reinterpret_cast<char*>(raw.data()), k * es, at + done * es);
    for (std::size_t i = 0; i < k; ++i) dst[done + i] = file_value(raw.data() + i * es, plan.dtype);
  }
}

// INTERPATCH_MPI_TIMINGS=1: each process prints one line, after the output is in
// place, of the seconds each stage took and the bytes it sent to other processes
// (docs/BENCHMARKS.md, "Split between MPI processes").
class Stages {
 public:
  explicit Stages(int rank) : rank_(rank), on_(std::getenv("INTERPATCH_MPI_TIMINGS") != nullptr), t_(clock()) {}
  void done(const char* stage, std::uint64_t sent = 0) {
    if (!on_) return;
    const double now = clock();
    text_ += cat(text_.empty() ? "" : ", ", "\"", stage, "\": [", now - t_, ", ", sent, ", ", peak_mib(), "]");
    t_ = now;
  }
  void print() const {
    if (on_) std::fprintf(stderr, "interpatch: rank %d stages (seconds, bytes sent, peak MiB so far): {%s}\n", rank_, text_.c_str());
  }

 private:
  // The process's peak resident memory so far (VmHWM), MiB.
  static long peak_mib() {
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);)
      if (line.rfind("VmHWM:", 0) == 0) return std::atol(line.c_str() + 6) / 1024;
    return -1;
  }
  static double clock() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  int rank_;
  bool on_;
  double t_;
  std::string text_;
};

// The coordinates of points as doubles (Vec3 is three doubles); null for none, where
// &p->x would dereference nothing.
static_assert(sizeof(Vec3) == 3 * sizeof(double), "points are read and moved as triples of doubles");
double* doubles(Vec3* p) { return reinterpret_cast<double*>(p); }

// Gives a buffer's memory back now (v = {} would keep its capacity).
void release(std::vector<Vec3>& v) { std::vector<Vec3>().swap(v); }

// A grid of D dimensions with every extent but the first from `n`.
template <std::size_t D>
Grid<Vec3, D> rows_grid(const std::array<std::size_t, 3>& n, std::size_t rows) {
  typename Grid<Vec3, D>::shape_type s{};
  s[0] = rows;
  for (std::size_t a = 1; a < D; ++a) s[a] = n[a];
  return Grid<Vec3, D>(s, for_overwrite);
}

// This process's rows of the points, and the few rows of the others it looks at.
template <std::size_t D>
struct RowBlock {
  std::array<std::size_t, 3> n{};  // the grid's extents
  std::size_t M = 1, first = 0, count = 0;
  // C order. Not a Grid: a Grid's buffer, freed, is kept for reuse
  // (base/pages.cpp), which would hold a second share of the data here.
  std::vector<Vec3> rows;
  std::array<Grid<Vec3, D>, 5> halo;  // the row before the block; rows 0, 1, n−2, n−1
};

template <std::size_t D>
RowBlock<D> read_block(const Plan& plan, const mpi::Team& team) {
  RowBlock<D> b;
  std::array<std::size_t, 3>& n = b.n;
  for (std::size_t a = 0; a < D; ++a) n[a] = plan.header.shape[a];
  for (std::size_t a = 1; a < D; ++a) b.M *= n[a];
  const std::size_t M = b.M;
  // Plain variables, not a structured binding: lambdas capture them (clang 14 refuses bindings).
  const std::pair<std::size_t, std::size_t> block = mpi::chunk_block(n[0], team.rank(), team.size());
  const std::size_t first = b.first = block.first, count = b.count = block.second;
  team.run([&] {
    require_memory(count * M, sizeof(Vec3), cat("/points: this process's ", count, " rows of the grid"));
    b.rows.resize(count * M);
    io::reader::at("/points", [&] {
      const mpi::InputFile file(plan.points, team);
      read_rows(file, plan, 3 * M, first, count, doubles(b.rows.data()));
      const std::size_t at[5] = {first > 0 ? first - 1 : 0, 0, std::min<std::size_t>(1, n[0] - 1), n[0] < 2 ? 0 : n[0] - 2,
                                 n[0] - 1};
      for (std::size_t h = 0; h < 5; ++h) {
        b.halo[h] = rows_grid<D>(n, 1);
        read_rows(file, plan, 3 * M, at[h], 1, doubles(b.halo[h].data()));
      }
    });
  });
  return b;
}

// The rows of the output a process writes ({first, count}) and the control rows
// they need, [lo, hi] (past the end around a periodic u): for build an even share of
// the N control rows, for eval those of its share of the output grid's rows. `type`
// names the spec's type in messages.
struct OutputRows {
  Resolution grid{};
  std::vector<double> us;
  std::size_t first = 0, count = 0;
  long long lo = 0, hi = -1;
};

template <std::size_t D>
OutputRows output_rows(const MpiRequest& r, const Plan& plan, const mpi::Team& team, const KnotVector& ku, std::size_t N,
                       const char* type) {
  OutputRows o;
  const int P = team.size();
  if (r.build) {
    std::tie(o.first, o.count) = mpi::even_block(N, team.rank(), P);
    o.lo = static_cast<long long>(o.first);
    o.hi = o.lo + static_cast<long long>(o.count) - 1;
    return o;
  }
  Resolution& grid = o.grid;
  team.run([&] {
    grid = plan.counts.size() == 1 ? Resolution{plan.counts[0], plan.counts[0], D == 3 ? plan.counts[0] : 0}
                                   : Resolution{plan.counts[0], plan.counts[1], plan.counts.size() > 2 ? plan.counts[2] : 0};
    if (plan.counts.size() > 1 && (plan.counts.size() == 3) != (D == 3)) {
      io::Construction c;
      c.type = type;
      if constexpr (D == 3) c.exact = BSplineVolume(KnotVector::bezier(1), KnotVector::bezier(1), KnotVector::bezier(1), PointGrid3({2, 2, 2}));
      else c.exact = BSplineSurface(KnotVector::bezier(1), KnotVector::bezier(1), PointGrid({2, 2}));
      cli::check_counts_kind(c, grid_option, grid);
    }
    require_eval_room(grid, r.out);
  });
  std::tie(o.first, o.count) = mpi::even_block(grid.nu, team.rank(), P);
  const std::vector<double> all_us = linspace(0, 1, grid.nu);
  o.us.assign(all_us.begin() + static_cast<std::ptrdiff_t>(o.first),
              all_us.begin() + static_cast<std::ptrdiff_t>(o.first + o.count));
  long long prev = -1;
  for (const double u : o.us) {
    const double t = ku.periodic() ? ku.wrap(u) : std::clamp(u, ku.front(), ku.back());
    long long s = ku.find_span(t);
    if (s < prev) s += static_cast<long long>(N);  // wrapped past the end of a periodic u
    prev = s;
    if (o.hi < o.lo) o.lo = s - ku.degree();
    o.hi = s;
  }
  return o;
}

// Writes the output from control rows [o.lo, o.lo + window) (around a periodic u)
// of a net of `net_shape` points, row_size of them a row: build writes this
// process's even share of the rows into the archive, eval its rows of the output
// grid, evaluated.
template <std::size_t D>
void write_output(const MpiRequest& r, const mpi::Team& team, const std::vector<int>& degrees,
                  const std::vector<KnotVector>& knots, const std::vector<std::size_t>& net_shape,
                  const std::vector<Vec3>& cp, const OutputRows& o, std::size_t window, Stages& stages) {
  const std::size_t N = net_shape[0];
  std::size_t row_size = 1;
  for (std::size_t a = 1; a < D; ++a) row_size *= net_shape[a];
  mpi::OutputFile file(r.out, team);
  if (r.build) {
    std::vector<const KnotVector*> kp;
    for (const KnotVector& k : knots) kp.push_back(&k);
    const std::size_t bytes = cp.size() * sizeof(Vec3);
    const std::vector<std::uint64_t> crcs = team.all(io::internal::crc32(cp.data(), bytes));
    const std::vector<std::uint64_t> lens = team.all(bytes);
    std::uint32_t crc = 0;
    for (std::size_t s = 0; s < crcs.size(); ++s)
      if (lens[s]) crc = io::internal::crc32_combine(crc, static_cast<std::uint32_t>(crcs[s]), lens[s]);
    const io::internal::NpzFrame frame = io::internal::exact_npz_frame(degrees, kp, net_shape, crc);
    team.run([&] {
      if (team.rank() == 0) {
        io::check_disk_space(r.out, frame.total, cat("the archive '", r.out, "'"));
        file.write(frame.head.data(), frame.head.size(), 0);
        file.write(frame.tail.data(), frame.tail.size(), frame.points_offset + std::uint64_t{N} * row_size * sizeof(Vec3));
      }
      file.write(cp.data(), bytes, frame.points_offset + std::uint64_t{o.first} * row_size * sizeof(Vec3));
    });
  } else {
    const std::vector<double> vs = linspace(0, 1, o.grid.nv), ws = D == 3 ? linspace(0, 1, o.grid.nw) : std::vector<double>{};
    const std::size_t per_row = o.grid.nv * (D == 3 ? o.grid.nw : 1);
    std::vector<std::size_t> out_shape{o.grid.nu, o.grid.nv};
    if (D == 3) out_shape.push_back(o.grid.nw);
    out_shape.push_back(3);
    const std::string header = io::internal::npy_header("<f8", out_shape);
    team.run([&] {
      require_memory(o.count * per_row, sizeof(Vec3), "this process's rows of the evaluation grid");
      std::vector<Vec3> out(o.count * per_row);
      const detail::RowWindow w{cp.data(), o.lo, window, N, row_size};
      if (o.count > 0) {
        if constexpr (D == 2) detail::evaluate_surface_rows(knots[0], knots[1], w, o.us, vs, out);
        else detail::evaluate_volume_rows(knots[0], knots[1], knots[2], w, o.us, vs, ws, out);
      }
      if (team.rank() == 0) file.write(header.data(), header.size(), 0);
      file.write(out.data(), out.size() * sizeof(Vec3), header.size() + std::uint64_t{o.first} * per_row * sizeof(Vec3));
    });
  }
  file.commit();
  stages.done(r.build ? "write" : "evaluate_write");
}

template <std::size_t D>
int split_run(const MpiRequest& r, const Plan& plan, const mpi::Team& team) {
  const int P = team.size();
  Stages stages(team.rank());
  io::reader::Context ctx;
  ctx.base_dir = plan.base;
  RowBlock<D> rb = read_block<D>(plan, team);
  std::array<std::size_t, 3> n = rb.n;
  std::size_t M = rb.M;
  const std::size_t first = rb.first, count = rb.count;
  std::vector<Vec3> rows = std::move(rb.rows);
  std::size_t nrows = count;
  std::array<Grid<Vec3, D>, 5> halo = std::move(rb.halo);
  // As the reader does: the first point that is not finite, named in the whole grid.
  team.run([&] {
    try {
      io::reader::check_finite_block({n.begin(), n.begin() + D}, {rows.data(), rows.size()}, first * M, "/points", plan.file);
    } catch (const error& e) {
      io::reader::rethrow_for_interpolation(e);
    }
  });

  stages.done("read");
  // The spec's options, then the checks and warnings of the single process.
  std::vector<std::optional<int>> degree;
  Parametrization param{};
  std::array<bool, 3> periodic{};
  team.run([&] {
    degree = io::reader::degrees(plan.spec, "", D);
    param = io::reader::parametrization(plan.spec, "");
    periodic = io::reader::periodic_flags(plan.spec, "", D);
  });
  detail::GridBlock b;
  auto set_block = [&] {
    b.rank = D;
    b.n = n;
    b.data = rows.data();
    b.first = first;
    b.count = nrows;
    b.before = halo[0].data();
    b.row0 = halo[1].data();
    b.last = halo[4].data();
  };
  set_block();
  const std::array<const Vec3*, 4> ends{halo[1].data(), halo[2].data(), halo[3].data(), halo[4].data()};
  team.run([&] {
    if (team.rank() == 0) (void)io::reader::check_fields(plan.spec, "", io::reader::find_type(D == 2 ? "interpolate" : "interpolate_volume")->fields, ctx);
  });
  const std::vector<std::size_t> shape(plan.header.shape.begin(), plan.header.shape.begin() + D);
  // check_grid_axes throws on every process alike (it sees what all see).
  team.run([&] {
    (void)io::reader::check_grid_axes(plan.spec, degree, periodic, shape, D == 2 ? "surface" : "volume",
                                      [&](std::size_t a) { return detail::block_closing(b, a, ends, false, team); }, ctx);
  });

  // Closed directions: a last line repeating the first is left out.
  std::array<bool, 3> dropped{};
  for (std::size_t a = 0; a < D; ++a) {
    if (!periodic[a] || !detail::block_closing(b, a, ends, true, team).dropped) continue;
    dropped[a] = true;
    if (a == 0) {
      --n[0];
      halo[4] = halo[3];  // the new last row
      if (first + nrows > n[0]) {
        nrows = n[0] - first;
        rows.resize(nrows * M);
      }
    } else {
      Grid<Vec3, D> g = rows_grid<D>(n, nrows);
      std::copy(rows.begin(), rows.end(), g.data());
      release(rows);
      detail::drop_last_line(g, a);
      rows.assign(g.data(), g.data() + g.size());
      for (auto& h : halo) detail::drop_last_line(h, a);
      --n[a];
      M = M / (n[a] + 1) * n[a];
    }
    set_block();
  }
  std::vector<int> p(D);
  static constexpr const char* in_axis[3] = {" in u", " in v", " in w"};
  static constexpr const char* around_axis[3] = {" around u (closed)", " around v (closed)", " around w (closed)"};
  team.run([&] {
    for (std::size_t a = 0; a < D; ++a) p[a] = detail::grid_degree(degree[a], n[a], periodic[a] ? around_axis[a] : in_axis[a]);
  });

  const int shift = param == Parametrization::uniform ? 0 : detail::block_shift(b, team);
  if (shift != 0) {
    team.run([&] { detail::check_finite(b); });
    detail::scale_points(rows.data(), rows.size(), -shift);
    for (auto& h : halo) detail::scale_points(h.data(), h.size(), -shift);
  }
  const std::vector<bool> closed(periodic.begin(), periodic.begin() + D);
  std::array<bool, 3> closed_arr = periodic;
  stages.done("checks");
  detail::RowSolution rs = detail::solve_rows(b, p, param, std::span<const bool>(closed_arr.data(), D), team);
  stages.done("rows");
  (void)closed;
  for (auto& h : halo) h = {};

  // Rows to columns: process s gets columns cols[s] of every row.
  std::vector<std::size_t> col_first(static_cast<std::size_t>(P)), col_count(static_cast<std::size_t>(P));
  for (int s = 0; s < P; ++s) std::tie(col_first[static_cast<std::size_t>(s)], col_count[static_cast<std::size_t>(s)]) = mpi::even_block(M, s, P);
  const std::size_t C = col_count[static_cast<std::size_t>(team.rank())];
  const std::vector<std::uint64_t> row_counts = team.all(nrows);
  std::vector<Vec3> columns;
  {
    std::vector<Vec3> send;
    std::vector<std::size_t> sc(static_cast<std::size_t>(P)), rc(static_cast<std::size_t>(P));
    team.run([&] {
      require_memory(rows.size(), sizeof(Vec3), "the transpose of this process's rows");
      send.resize(rows.size());
    });
    std::size_t at = 0;
    for (std::size_t s = 0; s < static_cast<std::size_t>(P); ++s) {
      for (std::size_t i = 0; i < nrows; ++i)
        std::copy_n(rows.data() + i * M + col_first[s], col_count[s], send.data() + at + i * col_count[s]);
      sc[s] = nrows * col_count[s];
      rc[s] = row_counts[s] * C;
      at += sc[s];
    }
    release(rows);
    team.run([&] {
      require_memory(n[0] * C, sizeof(Vec3), "this process's columns of the grid");
      columns.resize(n[0] * C);
    });
    team.exchange(send.data(), sc, columns.data(), rc);
    stages.done("to_columns", (send.size() - sc[static_cast<std::size_t>(team.rank())]) * sizeof(Vec3));
  }

  // Along u, on whole columns.
  detail::AxisSolver lu0 = detail::BandedLU(0, 0, 0);
  team.run([&] { lu0 = detail::factor_axis(rs.knots[0], rs.params[0], 0); });
  detail::solve_columns(lu0, doubles(columns.data()), n[0], 3 * C);
  if (shift != 0) detail::scale_points(columns.data(), columns.size(), shift);
  stages.done("solve_u");
  team.run([&] {
    if (!periodic[0] || p[0] % 2 != 0) return;
    Grid<Vec3, 2> g({n[0], C}, columns);
    release(columns);
    detail::insert_seam(g, 0, rs.knots[0], rs.params[0].front());
    columns.assign(g.data(), g.data() + g.size());
  });
  const std::size_t N = n[0] + (periodic[0] && p[0] % 2 == 0 ? 1 : 0);
  // The other axes' seams need their knots on every process, rows or none.
  std::array<std::size_t, 3> cn = n;  // extents of the control net
  cn[0] = N;

  // Which control rows each process needs: its share (build), or the window its
  // output rows' basis functions reach (eval), around a periodic u past the end.
  std::vector<KnotVector> knots = rs.knots;
  std::array<bool, 3> seam{};
  for (std::size_t a = 1; a < D; ++a) seam[a] = periodic[a] && p[a] % 2 == 0;
  // The knots after the seams along the rows (computed here, applied to the rows below).
  team.run([&] {
    for (std::size_t a = 1; a < D; ++a)
      if (seam[a]) {
        Grid<Vec3, D> none = rows_grid<D>(cn, 0);
        detail::insert_seam(none, a, knots[a], rs.params[a].front());
        cn[a] = static_cast<std::size_t>(knots[a].count());
      }
    bool unit = true;
    for (const KnotVector& k : knots) unit = unit && k.front() == 0.0 && k.back() == 1.0;
    if (!unit)
      for (KnotVector& k : knots) k = k.mapped(0.0, 1.0);
  });
  const OutputRows orows = output_rows<D>(r, plan, team, knots[0], N, D == 2 ? "interpolate" : "interpolate_volume");
  const long long lo = orows.lo;
  const std::size_t window = orows.hi >= lo ? static_cast<std::size_t>(orows.hi - lo + 1) : 0;

  // Columns back to rows: process s gets the rows of its window, from each column.
  const std::vector<std::uint64_t> los = team.all(static_cast<std::uint64_t>(lo)), counts = team.all(window);
  std::vector<Vec3> cp;
  {
    std::vector<std::size_t> sc(static_cast<std::size_t>(P)), rc(static_cast<std::size_t>(P));
    std::size_t send_total = 0;
    for (std::size_t s = 0; s < static_cast<std::size_t>(P); ++s) {
      sc[s] = counts[s] * C;
      rc[s] = window * col_count[s];
      send_total += sc[s];
    }
    std::vector<Vec3> send, recv;
    team.run([&] {
      require_memory(send_total, sizeof(Vec3), "the transpose of the control points");
      send.resize(send_total);
    });
    std::size_t at = 0;
    for (std::size_t s = 0; s < static_cast<std::size_t>(P); ++s)
      for (std::size_t v = 0; v < counts[s]; ++v, at += C)
        std::copy_n(columns.data() + ((static_cast<long long>(los[s]) + static_cast<long long>(v)) % static_cast<long long>(N)) * C, C,
                    send.data() + at);
    release(columns);
    team.run([&] {
      require_memory(window * M, sizeof(Vec3), "this process's rows of the control points");
      recv.resize(window * M);
    });
    team.exchange(send.data(), sc, recv.data(), rc);
    stages.done("to_rows", (send.size() - sc[static_cast<std::size_t>(team.rank())]) * sizeof(Vec3));
    release(send);
    team.run([&] {
      require_memory(window * M, sizeof(Vec3), "this process's rows of the control points");
      cp.resize(window * M);
    });
    at = 0;
    for (std::size_t s = 0; s < static_cast<std::size_t>(P); ++s)
      for (std::size_t v = 0; v < window; ++v, at += col_count[s])
        std::copy_n(recv.data() + at, col_count[s], cp.data() + v * M + col_first[s]);
  }
  team.run([&] {
    std::array<std::size_t, 3> extents = n;
    for (std::size_t a = 1; a < D; ++a)
      if (seam[a]) {
        Grid<Vec3, D> g = rows_grid<D>(extents, window);
        std::copy(cp.begin(), cp.end(), g.data());
        release(cp);
        KnotVector k = rs.knots[a];
        detail::insert_seam(g, a, k, rs.params[a].front());
        extents[a] = g.extent(a);
        cp.assign(g.data(), g.data() + g.size());
      }
  });

  std::vector<std::size_t> net_shape{N};
  for (std::size_t a = 1; a < D; ++a) net_shape.push_back(cn[a]);
  write_output<D>(r, team, std::vector<int>(p.begin(), p.end()), knots, net_shape, cp, orows, window, stages);
  stages.print();
  if (team.rank() == 0)
    for (const std::string& w : ctx.warnings) std::fprintf(stderr, "interpatch: warning: %s\n", w.c_str());
  return 0;
}

// The control rows [lo, lo + window) of a net of N rows of `width` points (modulo N
// around a periodic u), from the processes holding them: this one rows
// [first, first + mine.size() / width).
std::vector<Vec3> window_rows(const std::vector<Vec3>& mine, std::size_t first, std::size_t N, std::size_t width, long long lo,
                              std::size_t window, const mpi::Team& team) {
  const auto P = static_cast<std::size_t>(team.size());
  const std::vector<std::uint64_t> los = team.all(static_cast<std::uint64_t>(lo)), counts = team.all(window);
  const std::vector<std::uint64_t> firsts = team.all(first), held = team.all(width ? mine.size() / width : 0);
  auto row_of = [&](long long v) {
    const auto n = static_cast<long long>(N);
    return static_cast<std::size_t>(((v % n) + n) % n);
  };
  auto owner = [&](std::size_t g) {
    std::size_t s = 0;
    while (s + 1 < P && !(g >= firsts[s] && g < firsts[s] + held[s])) ++s;
    return s;
  };
  std::vector<Vec3> send, recv(window * width), out(window * width);
  std::vector<std::size_t> sc(P, 0), rc(P, 0);
  for (std::size_t s = 0; s < P; ++s)
    for (std::uint64_t v = 0; v < counts[s]; ++v) {
      const std::size_t g = row_of(static_cast<long long>(los[s]) + static_cast<long long>(v));
      if (g < first || g >= first + held[static_cast<std::size_t>(team.rank())]) continue;
      send.insert(send.end(), mine.begin() + static_cast<std::ptrdiff_t>((g - first) * width),
                  mine.begin() + static_cast<std::ptrdiff_t>((g - first + 1) * width));
      sc[s] += width;
    }
  for (std::size_t v = 0; v < window; ++v) rc[owner(row_of(lo + static_cast<long long>(v)))] += width;
  team.exchange(send.data(), sc, recv.data(), rc);
  // From each process its rows of the window, in window order.
  std::vector<std::size_t> at(P, 0);
  for (std::size_t s = 1; s < P; ++s) at[s] = at[s - 1] + rc[s - 1];
  for (std::size_t v = 0; v < window; ++v) {
    const std::size_t s = owner(row_of(lo + static_cast<long long>(v)));
    std::copy_n(recv.data() + at[s], width, out.data() + v * width);
    at[s] += width;
  }
  return out;
}

// An approximation split between the processes: detail::approximate_rows on the
// blocks of rows, then the output as for an interpolation.
int approximate_run(const MpiRequest& r, const Plan& plan, const mpi::Team& team) {
  Stages stages(team.rank());
  io::reader::Context ctx;
  ctx.base_dir = plan.base;
  team.run([&] {
    if (team.rank() == 0) (void)io::reader::check_fields(plan.spec, "", io::reader::find_type("approximate")->fields, ctx);
  });
  RowBlock<2> rb = read_block<2>(plan, team);
  // As the reader does: NaN marks a missing point, infinity is refused.
  team.run([&] {
    io::reader::check_finite_block({rb.n[0], rb.n[1]}, {rb.rows.data(), rb.rows.size()}, rb.first * rb.M, "/points", plan.file,
                                   true);
  });
  stages.done("read");
  detail::GridBlock b;
  b.rank = 2;
  b.n = rb.n;
  b.data = rb.rows.data();
  b.first = rb.first;
  b.count = rb.count;
  b.before = rb.halo[0].data();
  b.row0 = rb.halo[1].data();
  b.last = rb.halo[4].data();
  b.ends = {rb.halo[1].data(), rb.halo[2].data(), rb.halo[3].data(), rb.halo[4].data()};
  // As in one process: data beyond 2^±64 are fitted in a power of two of their own
  // size (exact both ways), the unit agreed over every process's rows.
  double top[1] = {detail::largest_coordinate(rb.rows)};
  team.max(top);
  const double unit = detail::approximation_unit(top[0]);
  SurfaceApproximationOptions options = plan.approx;
  if (unit != 1) {
    for (Vec3& q : rb.rows) q = q * (1 / unit);
    for (auto& h : rb.halo)
      for (Vec3& q : h.values()) q = q * (1 / unit);
    if (options.tolerance)
      options.tolerance = std::max(*options.tolerance / unit, std::numeric_limits<double>::denorm_min());
  }
  detail::ApproxRows fit;
  io::reader::at("/points", [&] { fit = detail::approximate_rows(b, options, team, [&] { release(rb.rows); }); });
  release(rb.rows);
  for (Vec3& q : fit.rows) q = q * unit;
  stages.done("fit");
  const std::size_t N = fit.net[0], width = fit.net[1];
  const OutputRows o = output_rows<2>(r, plan, team, fit.knots[0], N, "approximate");
  const std::size_t window = o.hi >= o.lo ? static_cast<std::size_t>(o.hi - o.lo + 1) : 0;
  const std::vector<Vec3> cp = window_rows(fit.rows, fit.first, N, width, o.lo, window, team);
  stages.done("to_rows");
  write_output<2>(r, team, {fit.degree[0], fit.degree[1]}, {fit.knots[0], fit.knots[1]}, {N, width}, cp, o, window, stages);
  stages.print();
  if (team.rank() == 0)
    for (const std::string& w : ctx.warnings) std::fprintf(stderr, "interpatch: warning: %s\n", w.c_str());
  return 0;
}

}  // namespace

int mpi_command(const MpiRequest& request, const std::function<int()>& single) {
  const mpi::Session session;
  const mpi::Team team(status_of);
  try {
    Plan plan;
    team.run([&] { plan = plan_of(request, team); });
    int split[1] = {plan.split ? 1 : 0};
    {
      std::size_t s[1] = {static_cast<std::size_t>(split[0])};
      team.min(s);
      split[0] = static_cast<int>(s[0]);
    }
    if (split[0] == 0) return team.await(team.rank() == 0 ? single() : 0);
    if (plan.approximate) return approximate_run(request, plan, team);
    return plan.dims == 3 ? split_run<3>(request, plan, team) : split_run<2>(request, plan, team);
  } catch (const detail::peer_failure& p) {
    return p.status;
  } catch (...) {
    return report_failure(std::current_exception());
  }
}

}  // namespace interpatch::cli

extern "C" int interpatch_mpi_command(const interpatch::cli::MpiRequest* request, const std::function<int()>* single) {
  return interpatch::cli::mpi_command(*request, *single);
}
