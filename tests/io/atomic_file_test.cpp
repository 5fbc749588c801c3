#include "interpatch/io/atomic_file.hpp"

#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch::io {
namespace {
namespace fs = std::filesystem;

using test::TempDir;

using test::read_text;

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
}

mode_t mode_of(const fs::path& p) {
  struct stat st {};
  EXPECT_EQ(::stat(p.c_str(), &st), 0);
  return st.st_mode & 07777;
}

/// Sets the umask for the life of the object.
class UmaskGuard {
 public:
  explicit UmaskGuard(mode_t mask) : old_(::umask(mask)) {}
  UmaskGuard(const UmaskGuard&) = delete;
  UmaskGuard& operator=(const UmaskGuard&) = delete;
  ~UmaskGuard() { ::umask(old_); }

 private:
  mode_t old_;
};

/// Sets durable_writes() for the life of the object: the setting is process-wide.
class DurableWritesGuard {
 public:
  explicit DurableWritesGuard(bool on) : old_(durable_writes()) { set_durable_writes(on); }
  DurableWritesGuard(const DurableWritesGuard&) = delete;
  DurableWritesGuard& operator=(const DurableWritesGuard&) = delete;
  ~DurableWritesGuard() { set_durable_writes(old_); }

 private:
  bool old_;
};

TEST(AtomicFile, WritesNewFile) {
  TempDir dir;
  write_atomically(dir / "out.txt", [](std::ostream& os) { os << "hello\n" << 42 << '\n'; });
  EXPECT_EQ(read_text(dir / "out.txt"), "hello\n42\n");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});  // no temporary file left
}

TEST(AtomicFile, ReplacesExistingFile) {
  TempDir dir;
  write_text(dir / "out.txt", "old content that is longer than the new one\n");
  write_atomically(dir / "out.txt", [](std::ostream& os) { os << "new\n"; });
  EXPECT_EQ(read_text(dir / "out.txt"), "new\n");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});
}

TEST(AtomicFile, RelativePathInCurrentDirectory) {
  TempDir dir;
  const fs::path old = fs::current_path();
  fs::current_path(dir.path());
  write_atomically("plain.txt", [](std::ostream& os) { os << "x"; });
  fs::current_path(old);
  EXPECT_EQ(read_text(dir / "plain.txt"), "x");
}

TEST(AtomicFile, LargeOutputInManyPieces) {
  TempDir dir;
  std::string expected;
  auto g = test::rng(31);
  for (int i = 0; i < 200000; ++i) expected += std::to_string(g()) + (i % 7 == 0 ? "\n" : " ");
  const std::string block(5u << 20, 'b');  // larger than the write buffer
  expected += block;
  write_atomically(dir / "big.txt", [&](std::ostream& os) {
    std::size_t pos = 0;
    for (std::size_t n = 1; pos < expected.size() - block.size(); n = n * 3 % 1001 + 1) {
      const std::size_t take = std::min(n, expected.size() - block.size() - pos);
      os.write(expected.data() + pos, static_cast<std::streamsize>(take));
      pos += take;
    }
    os << block;
  });
  EXPECT_TRUE(read_text(dir / "big.txt") == expected);
}

// Writes of every size interleaved: small ones gather in the buffer, large ones
// (from 64 KiB, even when the buffer has room for them) go straight to the file
// after what the buffer holds; the bytes land in the order written, and a seek back
// into them (as a ZIP writer does to fill in a header) still lands where it should.
TEST(AtomicFile, LargeWritesBetweenSmallOnesKeepTheirOrder) {
  TempDir dir;
  auto g = test::rng(32);
  std::string expected;
  const std::size_t sizes[] = {10, 70000, 5, (1u << 20) - 3, 100, 65535, 65536, 1, 3u << 20, 7, 200000, 0, 64};
  for (const std::size_t n : sizes)
    for (std::size_t k = 0; k < n; ++k) expected += static_cast<char>('a' + g() % 26);
  write_atomically(dir / "mixed.bin", [&](std::ostream& os) {
    std::size_t pos = 0;
    for (const std::size_t n : sizes) {
      os.write(expected.data() + pos, static_cast<std::streamsize>(n));
      pos += n;
    }
    os.seekp(12);  // inside the first large block
    os.write("XYZ", 3);
    os.seekp(0, std::ios::end);
  });
  expected.replace(12, 3, "XYZ");
  EXPECT_TRUE(read_text(dir / "mixed.bin") == expected);
}

TEST(AtomicFile, ThrowingWriterLeavesNoFile) {
  TempDir dir;
  EXPECT_THROW(write_atomically(dir / "out.txt",
                                [](std::ostream& os) {
                                  os << std::string(3u << 20, 'x');  // some of it reached the disk
                                  throw std::runtime_error("writer failed");
                                }),
               std::runtime_error);
  EXPECT_FALSE(fs::exists(dir / "out.txt"));
  EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicFile, ThrowingWriterKeepsExistingFile) {
  TempDir dir;
  write_text(dir / "out.txt", "precious\n");
  EXPECT_ERRC(write_atomically(dir / "out.txt",
                               [](std::ostream& os) {
                                 os << "half a file";
                                 throw error(errc::not_finite, "point 7 is nan");
                               }),
              not_finite, "point 7 is nan");  // the writer's error, unchanged
  EXPECT_EQ(read_text(dir / "out.txt"), "precious\n");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});
}

TEST(AtomicFile, StreamFailureBecomesFileUnwritable) {
  TempDir dir;
  write_text(dir / "out.txt", "precious\n");
  EXPECT_ERRC(write_atomically(dir / "out.txt", [](std::ostream& os) { os.setstate(std::ios::badbit); }),
              file_unwritable, "out.txt");
  EXPECT_EQ(read_text(dir / "out.txt"), "precious\n");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});
}

TEST(AtomicFile, WriteErrorFromTheSystemBecomesFileUnwritable) {
  // A file size limit makes write() fail with EFBIG, as a full disk fails with ENOSPC.
  TempDir dir;
  write_text(dir / "out.txt", "precious\n");
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  rlimit small = old;
  small.rlim_cur = 4096;
  auto* old_handler = std::signal(SIGXFSZ, SIG_IGN);
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  bool threw = false;
  try {
    write_atomically(dir / "out.txt", [](std::ostream& os) {
      for (int i = 0; i < 1000; ++i) os << std::string(10000, 'y');
    });
  } catch (const error& e) {
    threw = true;
    ::setrlimit(RLIMIT_FSIZE, &old);
    EXPECT_EQ(e.code(), errc::file_unwritable) << e.what();
    EXPECT_NE(std::string(e.what()).find("out.txt': File too large"), std::string::npos) << e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_TRUE(threw);
  EXPECT_EQ(read_text(dir / "out.txt"), "precious\n");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});
}

TEST(AtomicFile, NewFilePermissionsFollowUmaskNotMkstemp) {
  TempDir dir;
  {
    UmaskGuard mask(022);
    write_atomically(dir / "a.txt", [](std::ostream& os) { os << "a"; });
  }
  EXPECT_EQ(mode_of(dir / "a.txt"), 0644u);
  {
    UmaskGuard mask(027);
    write_atomically(dir / "b.txt", [](std::ostream& os) { os << "b"; });
  }
  EXPECT_EQ(mode_of(dir / "b.txt"), 0640u);
}

TEST(AtomicFile, ReplacedFileKeepsItsPermissions) {
  TempDir dir;
  write_text(dir / "secret.txt", "old");
  fs::permissions(dir / "secret.txt", fs::perms::owner_read | fs::perms::owner_write);
  write_atomically(dir / "secret.txt", [](std::ostream& os) { os << "new"; });
  EXPECT_EQ(mode_of(dir / "secret.txt"), 0600u);
  EXPECT_EQ(read_text(dir / "secret.txt"), "new");
}

TEST(AtomicFile, WritingThroughSymlinkReplacesTheTarget) {
  TempDir dir;
  write_text(dir / "target.txt", "old");
  fs::create_symlink("target.txt", dir / "link.txt");
  write_atomically(dir / "link.txt", [](std::ostream& os) { os << "new"; });
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir / "link.txt")));
  EXPECT_EQ(read_text(dir / "target.txt"), "new");
}

TEST(AtomicFile, CheckWritableAcceptsNewAndExistingFiles) {
  TempDir dir;
  EXPECT_NO_THROW(check_writable(dir / "new.txt"));
  write_text(dir / "old.txt", "x");
  EXPECT_NO_THROW(check_writable(dir / "old.txt"));
  EXPECT_TRUE(dir.entries() == std::vector<std::string>{"old.txt"});  // checking creates nothing
}

TEST(AtomicFile, CheckWritableMissingDirectoryIsNotCreated) {
  TempDir dir;
  EXPECT_ERRC(check_writable(dir / "missing" / "out.txt"), file_unwritable,
              "out.txt': directory '" + (dir / "missing").string() + "' does not exist");
  EXPECT_FALSE(fs::exists(dir / "missing"));
  EXPECT_ERRC(write_atomically(dir / "missing" / "out.txt", [](std::ostream& os) { os << "x"; }), file_unwritable,
              "does not exist");
  EXPECT_FALSE(fs::exists(dir / "missing"));
}

TEST(AtomicFile, CheckWritableRefusesDirectoryPath) {
  TempDir dir;
  fs::create_directory(dir / "sub");
  EXPECT_ERRC(check_writable(dir / "sub"), file_unwritable, "sub': it is a directory");
  EXPECT_ERRC(write_atomically(dir / "sub", [](std::ostream& os) { os << "x"; }), file_unwritable, "is a directory");
  EXPECT_TRUE(fs::is_directory(dir / "sub"));
}

TEST(AtomicFile, CheckWritableRefusesFileAsDirectory) {
  TempDir dir;
  write_text(dir / "plain", "x");
  EXPECT_ERRC(check_writable(dir / "plain" / "out.txt"), file_unwritable, "plain' is not a directory");
}

TEST(AtomicFile, CheckWritableRefusesEmptyPathAndSpecialFiles) {
  EXPECT_ERRC(check_writable(""), file_unwritable, "empty");
  TempDir dir;
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
  EXPECT_ERRC(check_writable(dir / "fifo"), file_unwritable, "fifo': it exists and is not a regular file");
}

TEST(AtomicFile, CheckWritableRefusesReadOnlyDirectory) {
  if (::geteuid() == 0) GTEST_SKIP() << "root writes into read-only directories";
  TempDir dir;
  fs::create_directory(dir / "ro");
  fs::permissions(dir / "ro", fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_ERRC(check_writable(dir / "ro" / "out.txt"), file_unwritable, "is not writable (Permission denied)");
  fs::permissions(dir / "ro", fs::perms::owner_all);
}

TEST(AtomicFile, CheckDiskSpaceAcceptsWhatFits) {
  TempDir dir;
  EXPECT_NO_THROW(check_disk_space(dir / "out.npy", 0, "nothing"));
  EXPECT_NO_THROW(check_disk_space(dir / "out.npy", 4096, "a small grid"));
  const fs::path old = fs::current_path();
  fs::current_path(dir.path());
  EXPECT_NO_THROW(check_disk_space("out.npy", 4096, "a small grid"));  // the current directory's file system
  fs::current_path(old);
  EXPECT_TRUE(dir.entries().empty());  // checking creates nothing
}

TEST(AtomicFile, CheckDiskSpaceRefusesMoreThanIsAvailable) {
  TempDir dir;
  const std::uintmax_t available = fs::space(dir.path()).available;
  // Half as much again as is free now, and at least 1 GB more: other processes
  // writing or deleting files while the test runs do not make it fit.
  constexpr std::uintmax_t margin = std::uintmax_t{1} << 30;
  if (available > (std::numeric_limits<std::uintmax_t>::max() - margin) / 2)
    GTEST_SKIP() << "the file system reports no limit on its free space";
  const std::uintmax_t bytes = available + available / 2 + margin;
  EXPECT_ERRC(check_disk_space(dir / "out.npy", bytes, "evaluation grid 9x9x9"), too_large,
              "evaluation grid 9x9x9 needs ");
  try {
    check_disk_space(dir / "out.npy", bytes, "evaluation grid 9x9x9");
  } catch (const error& e) {
    const std::string m = e.what();
    for (const std::string& part : {"(" + std::to_string(bytes) + " bytes)", std::string(" available on disk in "),
                                    "'" + dir.path().string() + "'"})
      EXPECT_NE(m.find(part), std::string::npos) << "message '" << m << "' lacks '" << part << "'";
  }
  EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicFile, DurableWritesAreOffByDefault) {
  EXPECT_FALSE(durable_writes());
  {
    DurableWritesGuard on(true);
    EXPECT_TRUE(durable_writes());
  }
  EXPECT_FALSE(durable_writes());
}

TEST(AtomicFile, DurableWritesGiveTheSameBytesAndReplaceTheOldFile) {
  TempDir dir;
  auto g = test::rng(32);
  std::string text;
  while (text.size() < (std::size_t{9} << 20)) text += std::to_string(g()) + '\n';  // several 4 MiB pieces
  const auto writer = [&](std::ostream& os) { os << text; };
  write_atomically(dir / "plain.txt", writer);
  write_text(dir / "durable.txt", "old content\n");
  {
    DurableWritesGuard on(true);
    write_atomically(dir / "durable.txt", writer);
    write_atomically(dir / "new.txt", writer);
    // A failed durable write keeps the old file as well.
    EXPECT_THROW(write_atomically(dir / "durable.txt",
                                  [](std::ostream& os) {
                                    os << "half";
                                    throw std::runtime_error("writer failed");
                                  }),
                 std::runtime_error);
  }
  EXPECT_FALSE(durable_writes());
  const std::string plain = read_text(dir / "plain.txt");
  EXPECT_TRUE(plain == text);
  EXPECT_TRUE(read_text(dir / "durable.txt") == plain);
  EXPECT_TRUE(read_text(dir / "new.txt") == plain);
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"durable.txt", "new.txt", "plain.txt"}));
}

}  // namespace
}  // namespace interpatch::io
