// bench/pure_io: the floor of a whole process that reads some files and writes one of
// a given size, and computes nothing. bench/compare times it next to `interpatch eval`
// (mesh, build) with the same input files and the same output size.
//
//   pure_io OUT BYTES IN...
//
// Reads every IN completely into memory as the interpatch command reads its data
// files: the whole file with pread in pieces of 1 MiB, on every OpenMP thread when it
// has at least 8 of them, each piece summed while it is in the cache (so that no read
// can be left out). Then writes OUT as interpatch writes its outputs, without fsync:
// a temporary file in OUT's directory, its space allocated at once (fallocate), a
// block of 4 MiB written again and again until BYTES, then renamed over OUT. The
// block holds the inputs' sum, so the writes depend on the reads. The inputs stay in
// memory until the output is in place, as a program's data would; buffers of 2 MiB
// or more are 2 MiB-aligned and marked for transparent huge pages, as interpatch's
// grids are.

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

constexpr std::size_t read_piece = std::size_t{1} << 20;
constexpr std::size_t write_block = std::size_t{4} << 20;

[[noreturn]] void fail(const std::string& what, int e) {
  throw std::runtime_error(what + ": " + std::strerror(e));
}

std::uint64_t sum_words(const std::byte* p, std::size_t n) {
  std::uint64_t s = 0;
  std::size_t k = 0;
  for (; k + 8 <= n; k += 8) {
    std::uint64_t w;
    std::memcpy(&w, p + k, 8);
    s += w;
  }
  for (; k < n; ++k) s += static_cast<std::uint64_t>(p[k]);
  return s;
}

struct FreeBytes {
  void operator()(std::byte* p) const noexcept { std::free(p); }
};
using Bytes = std::unique_ptr<std::byte[], FreeBytes>;

Bytes allocate(std::size_t n) {
  constexpr std::size_t huge = std::size_t{2} << 20;
  if (n < huge) {
    Bytes b(static_cast<std::byte*>(std::malloc(std::max<std::size_t>(n, 1))));
    if (!b) throw std::bad_alloc();
    return b;
  }
  const std::size_t size = (n + huge - 1) / huge * huge;
  Bytes b(static_cast<std::byte*>(std::aligned_alloc(huge, size)));
  if (!b) throw std::bad_alloc();
  (void)::madvise(b.get(), size, MADV_HUGEPAGE);  // advice only
  return b;
}

struct Input {
  Bytes bytes;
  std::size_t size = 0;
};

// The whole file, read in pieces by every thread; `sum` gets the sum of its words.
Input read_file(const std::string& path, std::uint64_t& sum) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) fail(path, errno);
  struct stat st {};
  if (::fstat(fd, &st) != 0) fail(path, errno);
  Input in{allocate(static_cast<std::size_t>(st.st_size)), static_cast<std::size_t>(st.st_size)};
  const auto pieces = static_cast<long long>((in.size + read_piece - 1) / read_piece);
  std::atomic<int> failure{0};
  std::uint64_t total = 0;
#pragma omp parallel for schedule(static) reduction(+ : total) if (in.size >= 8 * read_piece)
  for (long long k = 0; k < pieces; ++k) {
    const std::size_t begin = static_cast<std::size_t>(k) * read_piece, end = std::min(in.size, begin + read_piece);
    std::size_t at = begin;
    while (at < end && failure.load(std::memory_order_relaxed) == 0) {
      const ssize_t got = ::pread(fd, in.bytes.get() + at, end - at, static_cast<off_t>(at));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) {
        failure = got < 0 ? errno : EIO;
        break;
      }
      at += static_cast<std::size_t>(got);
    }
    total += sum_words(in.bytes.get() + begin, end - begin);
  }
  ::close(fd);
  if (const int e = failure.load(); e != 0) fail(path, e);
  sum += total;
  return in;
}

void write_file(const fs::path& target, std::size_t bytes, std::uint64_t sum) {
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const fs::path tmp = dir / ("." + target.filename().string() + ".pure_io-tmp." + std::to_string(::getpid()));
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail(tmp.string(), errno);
  if (bytes > 0) (void)::fallocate(fd, 0, 0, static_cast<off_t>(bytes));
  std::vector<std::uint64_t> block(std::min(bytes, write_block) / 8 + 1, sum);
  const auto* data = reinterpret_cast<const char*>(block.data());
  for (std::size_t done = 0; done < bytes;) {
    const ssize_t w = ::write(fd, data, std::min(bytes - done, write_block));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) fail(tmp.string(), w < 0 ? errno : EIO);
    done += static_cast<std::size_t>(w);
  }
  if (::close(fd) != 0) fail(tmp.string(), errno);
  if (::rename(tmp.c_str(), target.c_str()) != 0) fail(target.string(), errno);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: pure_io OUT BYTES IN...\n";
    return 2;
  }
  try {
    std::uint64_t sum = 0;
    std::vector<Input> inputs;
    for (int k = 3; k < argc; ++k) inputs.push_back(read_file(argv[k], sum));
    write_file(argv[1], static_cast<std::size_t>(std::stoull(argv[2])), sum);
  } catch (const std::exception& e) {
    std::cerr << "pure_io: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
