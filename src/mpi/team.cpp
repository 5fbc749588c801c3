#include "mpi/team.hpp"

#include <fcntl.h>
#include <mpi.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <thread>

#include "base/text.hpp"
#include "interpatch/error.hpp"

namespace interpatch::mpi {

namespace fs = std::filesystem;
using detail::cat;
using detail::fail;

namespace {

// A count MPI takes as an int.
int as_int(std::size_t n, const char* what) {
  if (n > static_cast<std::size_t>(INT_MAX))
    fail(errc::too_large, what, " of ", n, " items is more than one MPI message carries (", INT_MAX,
         "); run on more processes");
  return static_cast<int>(n);
}

std::string mpi_message(int code) {
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(code, text, &len);
  return std::string(text, static_cast<std::size_t>(len));
}

// n bytes in pieces an int counts (1 GiB): io(done, k) for each, in order.
template <class F>
void in_pieces(std::size_t n, const F& io) {
  constexpr std::size_t piece = std::size_t{1} << 30;
  for (std::size_t done = 0; done < n; done += std::min(piece, n - done)) io(done, std::min(piece, n - done));
}

MPI_Datatype point_type() {
  static MPI_Datatype t = [] {
    MPI_Datatype d;
    MPI_Type_contiguous(3, MPI_DOUBLE, &d);
    MPI_Type_commit(&d);
    return d;
  }();
  return t;
}

}  // namespace

Session::Session() {
  int provided = 0;
  // OpenMP threads work inside each process; only the main thread calls MPI.
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_ARE_FATAL);
}

Session::~Session() { MPI_Finalize(); }

Team::Team(Classify classify) : classify_(std::move(classify)) {
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

void Team::run(const std::function<void()>& step) const {
  std::exception_ptr failure;
  try {
    step();
  } catch (...) {
    failure = std::current_exception();
  }
  const int mine = failure ? rank_ : size_;
  int first = size_;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == size_) return;
  int status = rank_ == first ? classify_(failure) : 0;
  MPI_Bcast(&status, 1, MPI_INT, first, MPI_COMM_WORLD);
  if (rank_ == first) std::rethrow_exception(failure);
  throw detail::peer_failure{status};
}

void Team::max(std::span<double> values) const {
  MPI_Allreduce(MPI_IN_PLACE, values.data(), as_int(values.size(), "a reduction"), MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
}

void Team::min(std::span<std::size_t> values) const {
  static_assert(sizeof(std::size_t) == sizeof(unsigned long));
  MPI_Allreduce(MPI_IN_PLACE, values.data(), as_int(values.size(), "a reduction"), MPI_UNSIGNED_LONG, MPI_MIN,
                MPI_COMM_WORLD);
}

void Team::sum(std::span<std::size_t> values) const {
  MPI_Allreduce(MPI_IN_PLACE, values.data(), as_int(values.size(), "a reduction"), MPI_UNSIGNED_LONG, MPI_SUM,
                MPI_COMM_WORLD);
}

void Team::fold(std::span<double> acc, const std::function<void(std::span<double>)>& add) const {
  // In process order, as the single process adds its chunks: floating-point sums
  // depend on their order, so this is a relay, not a reduction.
  const int n = as_int(acc.size(), "a running sum");
  if (rank_ > 0) MPI_Recv(acc.data(), n, MPI_DOUBLE, rank_ - 1, 1, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  add(acc);
  if (rank_ + 1 < size_) MPI_Send(acc.data(), n, MPI_DOUBLE, rank_ + 1, 1, MPI_COMM_WORLD);
  MPI_Bcast(acc.data(), n, MPI_DOUBLE, size_ - 1, MPI_COMM_WORLD);
}

std::vector<double> Team::gather(std::span<const double> mine) const {
  const std::vector<std::uint64_t> counts = all(mine.size());
  std::vector<int> c(counts.size()), d(counts.size());
  std::size_t total = 0;
  for (std::size_t r = 0; r < counts.size(); ++r) {
    c[r] = as_int(counts[r], "a gather");
    d[r] = as_int(total, "a gather");
    total += counts[r];
  }
  std::vector<double> out(total);
  MPI_Allgatherv(mine.data(), c[static_cast<std::size_t>(rank_)], MPI_DOUBLE, out.data(), c.data(), d.data(), MPI_DOUBLE,
                 MPI_COMM_WORLD);
  return out;
}

std::vector<std::uint64_t> Team::all(std::uint64_t mine) const {
  std::vector<std::uint64_t> out(static_cast<std::size_t>(size_));
  MPI_Allgather(&mine, 1, MPI_UINT64_T, out.data(), 1, MPI_UINT64_T, MPI_COMM_WORLD);
  return out;
}

int Team::await(int value) const {
  MPI_Request request;
  MPI_Ibcast(&value, 1, MPI_INT, 0, MPI_COMM_WORLD, &request);
  for (int done = 0;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return value;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

std::string Team::broadcast(std::string text) const {
  unsigned long n = text.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG, 0, MPI_COMM_WORLD);
  text.resize(n);
  MPI_Bcast(text.data(), as_int(n, "a broadcast"), MPI_CHAR, 0, MPI_COMM_WORLD);
  return text;
}

void Team::exchange(const Vec3* send, std::span<const std::size_t> send_counts, Vec3* recv,
                    std::span<const std::size_t> recv_counts) const {
  const auto P = static_cast<std::size_t>(size_);
  std::vector<int> sc(P), sd(P), rc(P), rd(P);
  std::size_t s = 0, r = 0;
  for (std::size_t k = 0; k < P; ++k) {
    sc[k] = as_int(send_counts[k], "a transpose block");
    sd[k] = as_int(s, "a transpose");
    rc[k] = as_int(recv_counts[k], "a transpose block");
    rd[k] = as_int(r, "a transpose");
    s += send_counts[k];
    r += recv_counts[k];
  }
  MPI_Alltoallv(send, sc.data(), sd.data(), point_type(), recv, rc.data(), rd.data(), point_type(), MPI_COMM_WORLD);
}

std::pair<std::size_t, std::size_t> chunk_block(std::size_t rows, int r, int size) {
  const std::size_t chunks = (rows + detail::rows_per_chunk - 1) / detail::rows_per_chunk;
  const auto P = static_cast<std::size_t>(size), k = static_cast<std::size_t>(r);
  const std::size_t c0 = chunks * k / P, c1 = chunks * (k + 1) / P;
  const std::size_t first = std::min(rows, c0 * detail::rows_per_chunk);
  return {first, std::min(rows, c1 * detail::rows_per_chunk) - first};
}

std::pair<std::size_t, std::size_t> even_block(std::size_t n, int r, int size) {
  return detail::even_share(n, static_cast<std::size_t>(r), static_cast<std::size_t>(size));
}

// ---------------------------------------------------------------------------

InputFile::InputFile(const fs::path& path, const Team& team) : path_(path) {
  (void)team;
  std::error_code ec;
  if (fs::is_directory(path, ec)) fail(errc::file_unreadable, "cannot read '", path.string(), "': it is a directory");
  MPI_File f = MPI_FILE_NULL;
  // Each process opens the file on its own: a process that cannot read it fails
  // alone, and the team agrees on the failure (Team::run) without a hang.
  if (const int rc = MPI_File_open(MPI_COMM_SELF, path.c_str(), MPI_MODE_RDONLY, MPI_INFO_NULL, &f); rc != MPI_SUCCESS) {
    const int e = errno;
    fail(errc::file_unreadable, "cannot open '", path.string(), "': ",
         ::access(path.c_str(), R_OK) != 0 ? std::strerror(errno) : (e ? std::strerror(e) : mpi_message(rc).c_str()));
  }
  file_ = f;
  MPI_Offset size = 0;
  MPI_File_get_size(f, &size);
  size_ = static_cast<std::uint64_t>(size);
}

InputFile::~InputFile() {
  auto f = static_cast<MPI_File>(file_);
  if (f != MPI_FILE_NULL) MPI_File_close(&f);
}

void InputFile::read(char* dst, std::size_t n, std::uint64_t offset) const {
  in_pieces(n, [&](std::size_t done, std::size_t k) {
    MPI_Status st;
    const int rc =
        MPI_File_read_at(static_cast<MPI_File>(file_), static_cast<MPI_Offset>(offset + done), dst + done, static_cast<int>(k), MPI_BYTE, &st);
    int got = 0;
    MPI_Get_count(&st, MPI_BYTE, &got);
    if (rc != MPI_SUCCESS || static_cast<std::size_t>(got) != k)
      fail(errc::file_unreadable, "'", path_.string(), "': cannot read ", k, " bytes at offset ", offset + done,
           rc != MPI_SUCCESS ? ": " + mpi_message(rc) : cat(": got ", got));
  });
}

void InputFile::read_strided(char* dst, std::size_t runs, std::size_t run, std::uint64_t stride, std::uint64_t offset) const {
  auto f = static_cast<MPI_File>(file_);
  // Groups of runs an int counts, each read through a file view of that many runs.
  constexpr std::size_t piece = std::size_t{1} << 30;
  const std::size_t group = std::max<std::size_t>(1, piece / std::max<std::size_t>(run, 1));
  const int len = as_int(run, "a run of a strided read");
  for (std::size_t r0 = 0; r0 < runs; r0 += group) {
    const std::size_t g = std::min(group, runs - r0);
    MPI_Datatype view;
    MPI_Type_create_hvector(as_int(g, "a strided read"), len, static_cast<MPI_Aint>(stride), MPI_BYTE, &view);
    MPI_Type_commit(&view);
    MPI_File_set_view(f, static_cast<MPI_Offset>(offset + r0 * stride), MPI_BYTE, view, "native", MPI_INFO_NULL);
    MPI_Status st;
    const int rc = MPI_File_read(f, dst + r0 * run, as_int(g * run, "a strided read"), MPI_BYTE, &st);
    int got = 0;
    MPI_Get_count(&st, MPI_BYTE, &got);
    MPI_File_set_view(f, 0, MPI_BYTE, MPI_BYTE, "native", MPI_INFO_NULL);
    MPI_Type_free(&view);
    if (rc != MPI_SUCCESS || static_cast<std::size_t>(got) != g * run)
      fail(errc::file_unreadable, "'", path_.string(), "': cannot read ", g, " runs of ", run, " bytes from offset ",
           offset + r0 * stride, rc != MPI_SUCCESS ? ": " + mpi_message(rc) : cat(": got ", got, " bytes"));
  }
}

// ---------------------------------------------------------------------------

OutputFile::OutputFile(const fs::path& path, const Team& team) : team_(team), path_(path) {
  std::string temp;
  team.run([&] {
    if (team.rank() != 0) return;
    // A name of its own in the output's directory: the rename is then atomic.
    std::random_device rd;
    const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
    for (int attempt = 0; attempt < 100 && temp.empty(); ++attempt) {
      const fs::path t = dir / cat(".", path.filename().string().substr(0, 180), ".interpatch-mpi.", ::getpid(), ".",
                                   std::to_string(rd() % 1000000));
      const int fd = ::open(t.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      if (fd >= 0) {
        ::close(fd);
        temp = t.string();
      } else if (errno != EEXIST) {
        fail(errc::file_unwritable, "cannot create a temporary file beside '", path.string(), "': ", std::strerror(errno));
      }
    }
    if (temp.empty()) fail(errc::file_unwritable, "cannot create a temporary file beside '", path.string(), "'");
  });
  temp_ = team.broadcast(temp);
  open_ = true;  // from here the destructor removes it
  team.run([&] {
    MPI_File f = MPI_FILE_NULL;
    if (const int rc = MPI_File_open(MPI_COMM_SELF, temp_.c_str(), MPI_MODE_WRONLY, MPI_INFO_NULL, &f); rc != MPI_SUCCESS)
      fail(errc::file_unwritable, "cannot open the temporary file beside '", path.string(), "': ", mpi_message(rc));
    file_ = f;
  });
}

void OutputFile::write(const void* data, std::size_t n, std::uint64_t offset) const {
  const char* bytes = static_cast<const char*>(data);
  in_pieces(n, [&](std::size_t done, std::size_t k) {
    MPI_Status st;
    const int rc = MPI_File_write_at(static_cast<MPI_File>(file_), static_cast<MPI_Offset>(offset + done), bytes + done,
                                     static_cast<int>(k), MPI_BYTE, &st);
    int put = 0;
    MPI_Get_count(&st, MPI_BYTE, &put);
    if (rc != MPI_SUCCESS || static_cast<std::size_t>(put) != k)
      fail(errc::file_unwritable, "'", path_.string(), "': cannot write ", k, " bytes at offset ", offset + done,
           rc != MPI_SUCCESS ? ": " + mpi_message(rc) : cat(": wrote ", put));
  });
}

void OutputFile::close() noexcept {
  auto f = static_cast<MPI_File>(file_);
  if (f != MPI_FILE_NULL) MPI_File_close(&f);
  file_ = nullptr;
}

void OutputFile::commit() {
  team_.run([&] {
    auto f = static_cast<MPI_File>(file_);
    file_ = nullptr;
    if (f != MPI_FILE_NULL)
      if (const int rc = MPI_File_close(&f); rc != MPI_SUCCESS)
        fail(errc::file_unwritable, "'", path_.string(), "': closing the file failed: ", mpi_message(rc));
  });
  // Every process has written and closed its part: the file is complete.
  team_.run([&] {
    if (team_.rank() != 0) return;
    if (::rename(temp_.c_str(), path_.c_str()) != 0)
      fail(errc::file_unwritable, "cannot rename the temporary file to '", path_.string(), "': ", std::strerror(errno));
  });
  open_ = false;
}

OutputFile::~OutputFile() {
  close();
  if (open_ && team_.rank() == 0) ::unlink(temp_.c_str());
}

}  // namespace interpatch::mpi
