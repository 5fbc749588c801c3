#pragma once
// The MPI side of a run split between processes (INTERPATCH_MPI): the processes of
// MPI_COMM_WORLD as a RowTeam (constructions/interpolate/grid_rows.hpp), with the
// all-to-all exchange the transposes between blocks of rows and blocks of columns
// use, the input file read in blocks, and the output file written in place by every
// process. The core library knows nothing of MPI; only this directory does.

#include <cstddef>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "constructions/interpolate/grid_rows.hpp"
#include "interpatch/vec3.hpp"

namespace interpatch::mpi {

/// The exit status a failure maps to (the command's rule).
using Classify = std::function<int(const std::exception_ptr&)>;

/// MPI_Init on construction, MPI_Finalize on destruction.
class Session {
 public:
  Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  ~Session();
};

class Team final : public detail::RowTeam {
 public:
  explicit Team(Classify classify);
  [[nodiscard]] int rank() const noexcept { return rank_; }
  [[nodiscard]] int size() const noexcept { return size_; }

  void run(const std::function<void()>& step) const override;
  void max(std::span<double> values) const override;
  void min(std::span<std::size_t> values) const override;
  void sum(std::span<std::size_t> values) const override;
  void fold(std::span<double> acc, const std::function<void(std::span<double>)>& add) const override;
  [[nodiscard]] std::vector<double> gather(std::span<const double> mine) const override;

  /// Sizes (any type of 8 bytes or less, as 64-bit) from every process, in order.
  [[nodiscard]] std::vector<std::uint64_t> all(std::uint64_t mine) const override;
  /// Rank 0's value, on every process; the others wait asleep (not spinning, as a
  /// blocking collective would, on cores rank 0 may need).
  [[nodiscard]] int await(int value) const;
  /// Rank 0's string, on every process.
  [[nodiscard]] std::string broadcast(std::string text) const;

  /// Points in blocks: send[r] goes to process r, recv[r] comes from it (points,
  /// counted per process; the buffers are laid out in process order).
  void exchange(const Vec3* send, std::span<const std::size_t> send_counts, Vec3* recv,
                std::span<const std::size_t> recv_counts) const override;
  [[nodiscard]] std::size_t processes() const override { return static_cast<std::size_t>(size_); }
  [[nodiscard]] std::size_t process() const override { return static_cast<std::size_t>(rank_); }

 private:
  Classify classify_;
  int rank_ = 0, size_ = 1;
};

/// The first `count` rows of [0, rows) that process r of `size` holds, in chunks of
/// detail::rows_per_chunk: {first, count}.
[[nodiscard]] std::pair<std::size_t, std::size_t> chunk_block(std::size_t rows, int r, int size);
/// An even split of n items: {first, count} of process r.
[[nodiscard]] std::pair<std::size_t, std::size_t> even_block(std::size_t n, int r, int size);

/// A file every process reads blocks of (MPI-IO).
class InputFile {
 public:
  InputFile(const std::filesystem::path& path, const Team& team);
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;
  ~InputFile();
  [[nodiscard]] std::uint64_t size() const noexcept { return size_; }
  /// n bytes at `offset` into dst, this process alone.
  void read(char* dst, std::size_t n, std::uint64_t offset) const;
  /// `runs` runs of `run` bytes each, `stride` bytes apart from `offset` on, into dst
  /// one after another (a strided view of the file), this process alone.
  void read_strided(char* dst, std::size_t runs, std::size_t run, std::uint64_t stride, std::uint64_t offset) const;

 private:
  std::filesystem::path path_;
  void* file_ = nullptr;  // MPI_File
  std::uint64_t size_ = 0;
};

/// An output file every process writes its part of (MPI-IO), under a temporary name
/// in the output's directory; commit() renames it into place (rank 0), and without
/// commit the temporary file is removed.
class OutputFile {
 public:
  OutputFile(const std::filesystem::path& path, const Team& team);
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile();
  /// n bytes at `offset`, this process alone.
  void write(const void* data, std::size_t n, std::uint64_t offset) const;
  /// Closes the file (collective); when every process has written its part, rank 0
  /// renames it to the output's name.
  void commit();

 private:
  void close() noexcept;
  const Team& team_;
  std::filesystem::path path_, temp_;
  void* file_ = nullptr;  // MPI_File
  bool open_ = false;
};

}  // namespace interpatch::mpi
