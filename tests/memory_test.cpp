#include "interpatch/memory.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>

#include "test_util.hpp"

namespace interpatch {
namespace {

/// MemTotal from /proc/meminfo in bytes, 0 if unknown.
std::uint64_t mem_total() {
  std::FILE* f = std::fopen("/proc/meminfo", "r");
  if (!f) return 0;
  char line[256];
  unsigned long long kb = 0;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "MemTotal: %llu kB", &kb) == 1) break;
  std::fclose(f);
  return kb * 1024;
}

TEST(Memory, AvailableIsPositiveAndAtMostPhysical) {
  const std::size_t avail = available_memory();
  EXPECT_GT(avail, std::size_t{1} << 20);  // a test machine has more than a megabyte free
  if (const auto total = mem_total(); total > 0) {
    EXPECT_LE(avail, total);
  }
}

TEST(Memory, SmallRequestsPass) {
  EXPECT_NO_THROW(require_memory(0, 8, "nothing"));
  EXPECT_NO_THROW(require_memory(1000, 0, "zero-size items"));
  EXPECT_NO_THROW(require_memory(1000, 24, "a thousand points"));
}

TEST(Memory, HugeRequestNamesWhatAndSizes) {
  // 1e15 bytes: a petabyte, on no test machine.
  EXPECT_ERRC(require_memory(1'000'000'000'000ull, 1000, "evaluation grid 1000000x1000000"), too_large,
              "evaluation grid 1000000x1000000 needs 1 PB (1000000000000000 bytes), ");
  EXPECT_ERRC(require_memory(1'000'000'000'000ull, 1000, "grid"), too_large, " available (");
}

TEST(Memory, HumanUnitsMatchTheDocumentedExample) {
  const std::size_t need = 100000ull * 100000ull * 24;  // 240 GB
  if (available_memory() >= need) GTEST_SKIP() << "this machine has 240 GB free";
  EXPECT_ERRC(require_memory(100000ull * 100000ull, 24, "evaluation grid 100000x100000"), too_large,
              "evaluation grid 100000x100000 needs 240 GB (240000000000 bytes), ");
  // Three significant digits and decimal units for the amount available too.
  try {
    require_memory(100000ull * 100000ull, 24, "g");
  } catch (const error& e) {
    const std::string msg = e.what();
    const auto comma = msg.find("), ");
    ASSERT_NE(comma, std::string::npos) << msg;
    const std::string rest = msg.substr(comma + 3);
    EXPECT_TRUE(rest.find(" GB available (") != std::string::npos || rest.find(" MB available (") != std::string::npos ||
                rest.find(" TB available (") != std::string::npos)
        << msg;
  }
}

TEST(Memory, ByteCountOverflowIsTooLarge) {
  const std::size_t max = std::numeric_limits<std::size_t>::max();
  EXPECT_ERRC(require_memory(max / 2 + 1, 4, "volume 4000000x4000000x4000000"), too_large,
              "volume 4000000x4000000x4000000 needs ");
  EXPECT_ERRC(require_memory(max, max, "x"), too_large, "more than this machine can address");
}

#if !defined(__SANITIZE_ADDRESS__)  // ASan reserves terabytes of address space
TEST(Memory, AddressSpaceLimitIsRespected) {
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_AS, &old), 0);
  std::uint64_t used_pages = 0;
  if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
    unsigned long long pages = 0;
    if (std::fscanf(f, "%llu", &pages) == 1) used_pages = pages;
    std::fclose(f);
  }
  if (used_pages == 0) GTEST_SKIP() << "no /proc/self/statm";
  const std::uint64_t used = used_pages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
  const std::uint64_t headroom = 256ull << 20;
  rlimit lim = old;
  lim.rlim_cur = static_cast<rlim_t>(used + headroom);
  if (old.rlim_max != RLIM_INFINITY && lim.rlim_cur > old.rlim_max) GTEST_SKIP() << "hard limit too low";
  ASSERT_EQ(::setrlimit(RLIMIT_AS, &lim), 0);
  const std::size_t avail = available_memory();
  bool refused = false;
  try {
    require_memory(std::size_t{1} << 30, 1, "a gigabyte");
  } catch (const error& e) {
    refused = e.code() == errc::too_large;
  }
  ::setrlimit(RLIMIT_AS, &old);
  EXPECT_LE(avail, headroom);
  EXPECT_GT(avail, headroom / 2);  // usage moved a little at most
  EXPECT_TRUE(refused);
}
#endif

}  // namespace
}  // namespace interpatch
