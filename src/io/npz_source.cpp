// Where an .npz archive's bytes come from: a file (pread, large blocks by every
// thread at once) or memory; and a member's bytes as a stream for the .npy reader.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

#include "io/crc32.hpp"
#include "io/npy_format.hpp"
#include "io/npz_archive.hpp"

namespace interpatch::io::internal::npz_io {

using detail::fail;

FileSource::FileSource(const std::filesystem::path& path, std::string name) : path_(path), name_(std::move(name)) {
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) {
    const int e = errno;
    fail(errc::file_unreadable, "cannot open '", name_, "': ", std::strerror(e));
  }
  struct stat st {};
  const bool known = ::fstat(fd_, &st) == 0;
  const int e = errno;
  if (!known || S_ISDIR(st.st_mode)) {
    ::close(fd_);  // no destructor runs for a constructor that throws
    if (!known) fail_read(e);
    fail(errc::file_unreadable, "cannot read '", name_, "': it is a directory");
  }
  size_ = static_cast<std::uint64_t>(st.st_size);
}

FileSource::~FileSource() { ::close(fd_); }

void FileSource::read(char* dst, std::size_t n, std::uint64_t offset) const {
  while (n > 0) {
    const ssize_t got = ::pread(fd_, dst, n, static_cast<off_t>(offset));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) fail_read(got < 0 ? errno : EIO);  // 0: the file shrank while being read
    dst += got;
    offset += static_cast<std::uint64_t>(got);
    n -= static_cast<std::size_t>(got);
  }
}

void FileSource::read_bulk(char* dst, std::size_t n, std::uint64_t offset, std::uint32_t* crc) const {
  internal::read_pieces(path_, name_, dst, n, offset, crc);
}

void FileSource::fail_read(int e) const {
  fail(errc::file_unreadable, "cannot read '", name_, "': ", std::strerror(e));
}

void MemorySource::read(char* dst, std::size_t n, std::uint64_t offset) const {
  if (n > 0) std::memcpy(dst, bytes_.data() + offset, n);
}

void MemorySource::read_bulk(char* dst, std::size_t n, std::uint64_t offset, std::uint32_t* crc) const {
  read(dst, n, offset);
  *crc = crc32(dst, n, *crc);
}

MemberBuffer::MemberBuffer(const Source& src, std::uint64_t begin, std::uint64_t size)
    : src_(src), begin_(begin), size_(size), buf_(static_cast<std::size_t>(std::min<std::uint64_t>(size, 1 << 16))) {}

std::uint32_t MemberBuffer::checksum() {
  crc_ = internal::crc32_serial(summed_, static_cast<std::size_t>(gptr() - summed_), crc_);
  summed_ = gptr();
  return crc_;
}

MemberBuffer::int_type MemberBuffer::underflow() {
  if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
  (void)checksum();
  if (next_ >= size_) return traits_type::eof();
  const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(buf_.size(), size_ - next_));
  src_.read(buf_.data(), n, begin_ + next_);
  next_ += n;
  setg(buf_.data(), buf_.data(), buf_.data() + n);
  summed_ = buf_.data();
  return traits_type::to_int_type(buf_[0]);
}

}  // namespace interpatch::io::internal::npz_io
