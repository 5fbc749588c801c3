// base/pages.hpp: zeroed working arrays whose pages are first touched where written.
#include "base/pages.hpp"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <utility>

#include "test_util.hpp"

namespace interpatch::detail {
namespace {

// This process's resident memory in bytes, from /proc/self/statm (0 if unknown).
std::size_t resident() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  unsigned long long size = 0, pages = 0;
  const int read = std::fscanf(f, "%llu %llu", &size, &pages);
  std::fclose(f);
  return read == 2 ? static_cast<std::size_t>(pages) * static_cast<std::size_t>(sysconf(_SC_PAGESIZE)) : 0;
}

// Every size starts as zeros, small (from the heap) and large (fresh from the system);
// values written stay; a copy has them, a move takes them and leaves the source empty.
TEST(Pages, ZeroedDoublesStartAtZeroAndCopyAndMove) {
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{1000}, std::size_t{3} << 20}) {
    ZeroedDoubles v(n);
    ASSERT_EQ(v.size(), n);
    EXPECT_EQ(v.empty(), n == 0);
    for (std::size_t k = 0; k < n; k += 997) ASSERT_EQ(v[k], 0.0) << n << " values, value " << k;
    for (std::size_t k = 0; k < n; k += 4099) v[k] = static_cast<double>(k) + 0.5;
    const ZeroedDoubles copy = v;
    ASSERT_EQ(copy.size(), n);
    for (std::size_t k = 0; k < n; k += 4099) EXPECT_EQ(copy[k], static_cast<double>(k) + 0.5);
    ZeroedDoubles moved = std::move(v);
    EXPECT_EQ(moved.size(), n);
    EXPECT_TRUE(v.empty());  // a moved-from array is empty
    EXPECT_EQ(v.data(), nullptr);
    moved = ZeroedDoubles(7);
    EXPECT_EQ(moved.size(), 7u);
    EXPECT_EQ(moved[6], 0.0);
  }
}

// A large array takes no memory until written: 64 MiB of zeros add less than 8 MiB to the
// resident set (allocator bookkeeping and whatever else the process touches meanwhile),
// and writing every 4096th value of it then adds most of it.
TEST(Pages, LargeZeroedDoublesAreTouchedOnlyWhereWritten) {
  const std::size_t before = resident();
  if (before == 0) GTEST_SKIP() << "no /proc/self/statm";
  const std::size_t n = std::size_t{8} << 20;  // 64 MiB
  ZeroedDoubles v(n);
  const std::size_t after = resident();
  EXPECT_LT(after, before + (std::size_t{8} << 20)) << "before " << before << ", after " << after;
  for (std::size_t k = 0; k < n; k += 512) v[k] = 1.0;  // one value per 4 KiB page
  EXPECT_GT(resident(), before + (std::size_t{48} << 20));
}

TEST(Pages, PagesLetGoReadZeroAndLeaveTheResidentSet) {
  const std::size_t n = std::size_t{8} << 20;  // 64 MiB
  ZeroedDoubles v(n);
  for (std::size_t k = 0; k < n; ++k) v[k] = static_cast<double>(k % 1000) + 1;
  const std::size_t full = resident();
  if (full == 0) GTEST_SKIP() << "no /proc/self/statm";
  const std::size_t kept = (std::size_t{16} << 20) + 12;  // bytes: 16 MiB and a part of a page
  v.let_go_after(kept);
  // Rounding up to the next page: nothing before `kept` is lost.
  for (std::size_t k = 0; k < kept / sizeof(double); ++k) ASSERT_EQ(v[k], static_cast<double>(k % 1000) + 1) << k;
  const std::size_t after = resident();
  // 48 MiB less the page the cut falls in, the rest of the resident set unchanged.
  EXPECT_LT(after + (std::size_t{44} << 20), full) << "full " << full << ", after " << after;
  // Every whole page past the cut reads zero (the block's last page may be partial).
  const auto base = reinterpret_cast<std::uintptr_t>(v.data());
  const std::uintptr_t from = (base + kept + 4095) / 4096 * 4096, to = (base + n * sizeof(double)) / 4096 * 4096;
  for (std::uintptr_t at = from; at < to; at += 8 * 97) ASSERT_EQ(v[(at - base) / sizeof(double)], 0.0) << at - base;
  v[n - 1] = 2.0;  // written again like any page
  EXPECT_EQ(v[n - 1], 2.0);
}

}  // namespace
}  // namespace interpatch::detail
