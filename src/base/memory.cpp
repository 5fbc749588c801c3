#include "interpatch/memory.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <string>

#include "base/text.hpp"

namespace interpatch {
namespace {

constexpr std::uint64_t unlimited = std::numeric_limits<std::uint64_t>::max();

// Everything here runs inside a noexcept function: plain C stdio, no exceptions.

/// The value of a "key value" or "Key: value kB" line of a small text file, scaled
/// by `unit`; nullopt when the file or the key is missing.
std::optional<std::uint64_t> read_keyed(const char* file, const char* key, std::uint64_t unit) {
  std::FILE* f = std::fopen(file, "re");
  if (!f) return std::nullopt;
  std::optional<std::uint64_t> result;
  char line[512];
  const std::size_t klen = std::strlen(key);
  while (std::fgets(line, sizeof line, f)) {
    if (std::strncmp(line, key, klen) != 0) continue;
    const char* p = line + klen;
    if (*p == ':') ++p;
    if (*p != ' ' && *p != '\t') continue;  // a longer key with the same prefix
    std::uint64_t v = 0;
    if (std::sscanf(p, "%" SCNu64, &v) == 1) result = v > unlimited / unit ? unlimited : v * unit;
    break;
  }
  std::fclose(f);
  return result;
}

/// The first number in a file ("max" counts as unlimited); nullopt if unreadable.
std::optional<std::uint64_t> read_number(const std::string& file) {
  std::FILE* f = std::fopen(file.c_str(), "re");
  if (!f) return std::nullopt;
  char buf[64] = {};
  const bool ok = std::fgets(buf, sizeof buf, f) != nullptr;
  std::fclose(f);
  if (!ok) return std::nullopt;
  if (std::strncmp(buf, "max", 3) == 0) return unlimited;
  std::uint64_t v = 0;
  if (std::sscanf(buf, "%" SCNu64, &v) != 1) return std::nullopt;
  return v;
}

/// The memory the system reports available (page cache that can be reclaimed included).
std::uint64_t system_available() {
  if (auto kb = read_keyed("/proc/meminfo", "MemAvailable", 1024)) return *kb;
  const long pages = sysconf(_SC_AVPHYS_PAGES);
  const long page = sysconf(_SC_PAGESIZE);
  if (pages > 0 && page > 0) return static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page);
  return unlimited;  // nothing known: do not refuse work on a guess
}

/// The address-space limit (ulimit -v) left to this process.
std::uint64_t address_space_available() {
  rlimit lim{};
  if (getrlimit(RLIMIT_AS, &lim) != 0 || lim.rlim_cur == RLIM_INFINITY) return unlimited;
  const auto limit = static_cast<std::uint64_t>(lim.rlim_cur);
  std::uint64_t used = 0;
  if (std::FILE* f = std::fopen("/proc/self/statm", "re")) {
    std::uint64_t pages = 0;
    if (std::fscanf(f, "%" SCNu64, &pages) == 1) used = pages * static_cast<std::uint64_t>(sysconf(_SC_PAGESIZE));
    std::fclose(f);
  }
  return limit > used ? limit - used : 0;
}

/// The path of this process's cgroup in the hierarchy that holds `controller`
/// (v1), or in the unified hierarchy (v2, controller nullptr).
std::optional<std::string> cgroup_path(const char* controller) {
  std::FILE* f = std::fopen("/proc/self/cgroup", "re");
  if (!f) return std::nullopt;
  std::optional<std::string> result;
  char line[1024];
  while (std::fgets(line, sizeof line, f)) {
    // "hierarchy-id:controller-list:path"
    char* c1 = std::strchr(line, ':');
    char* c2 = c1 ? std::strchr(c1 + 1, ':') : nullptr;
    if (!c2) continue;
    std::string path(c2 + 1);
    while (!path.empty() && (path.back() == '\n' || path.back() == '\r')) path.pop_back();
    const std::string list(c1 + 1, c2);
    if (controller == nullptr) {
      if (list.empty()) result = path;
    } else {
      std::size_t start = 0;
      while (start <= list.size()) {
        std::size_t end = list.find(',', start);
        if (end == std::string::npos) end = list.size();
        if (list.compare(start, end - start, controller) == 0) result = path;
        start = end + 1;
      }
    }
    if (result) break;
  }
  std::fclose(f);
  return result;
}

bool readable(const std::string& file) { return access(file.c_str(), R_OK) == 0; }

/// Room left under the cgroup v1 memory limit (hierarchical, so parent limits
/// count). Reclaimable page cache is not counted as used.
std::uint64_t cgroup_v1_available() {
  const std::string root = "/sys/fs/cgroup/memory";
  auto rel = cgroup_path("memory");
  std::string dir = rel ? root + *rel : root;
  // Inside a container the cgroup namespace may hide the path: use the mount root.
  if (!readable(dir + "/memory.stat")) dir = root;
  const std::string stat = dir + "/memory.stat";
  auto limit = read_keyed(stat.c_str(), "hierarchical_memory_limit", 1);
  if (!limit) limit = read_number(dir + "/memory.limit_in_bytes");
  // "Unlimited" in v1 is a huge page-aligned number near 2^63.
  if (!limit || *limit >= (std::uint64_t{1} << 62)) return unlimited;
  const std::uint64_t usage = read_number(dir + "/memory.usage_in_bytes").value_or(0);
  const std::uint64_t reclaimable = read_keyed(stat.c_str(), "total_inactive_file", 1).value_or(0);
  const std::uint64_t used = usage > reclaimable ? usage - reclaimable : 0;
  return *limit > used ? *limit - used : 0;
}

/// Room left under the cgroup v2 memory.max of this cgroup and of every ancestor.
std::uint64_t cgroup_v2_available() {
  const std::string root = "/sys/fs/cgroup";
  auto rel = cgroup_path(nullptr);
  if (!rel) return unlimited;
  std::string path = *rel;
  if (!readable(root + path + "/memory.max")) path = "";  // namespaced: the mount root is ours
  std::uint64_t best = unlimited;
  for (;;) {
    const std::string dir = root + path;
    if (auto max = read_number(dir + "/memory.max"); max && *max != unlimited) {
      const std::uint64_t current = read_number(dir + "/memory.current").value_or(0);
      const std::string stat = dir + "/memory.stat";
      const std::uint64_t reclaimable = read_keyed(stat.c_str(), "inactive_file", 1).value_or(0);
      const std::uint64_t used = current > reclaimable ? current - reclaimable : 0;
      best = std::min(best, *max > used ? *max - used : 0);
    }
    if (path.empty() || path == "/") break;
    const auto slash = path.find_last_of('/');
    path = slash == std::string::npos || slash == 0 ? std::string() : path.substr(0, slash);
  }
  return best;
}


}  // namespace

std::size_t available_memory() noexcept {
  std::uint64_t avail = system_available();
  avail = std::min(avail, address_space_available());
  avail = std::min(avail, cgroup_v2_available());
  avail = std::min(avail, cgroup_v1_available());
  return static_cast<std::size_t>(std::min<std::uint64_t>(avail, std::numeric_limits<std::size_t>::max()));
}

void require_memory(std::size_t count, std::size_t item_bytes, std::string_view what) {
  if (item_bytes != 0 && count > std::numeric_limits<std::size_t>::max() / item_bytes) {
    detail::fail(errc::too_large, std::string(what), " needs ", count, " x ", item_bytes,
                 " bytes, more than this machine can address");
  }
  const std::size_t need = count * item_bytes;
  const std::size_t avail = available_memory();
  if (need > avail) {
    detail::fail(errc::too_large, std::string(what), " needs ", detail::human_bytes(need), " (", need, " bytes), ",
                 detail::human_bytes(avail), " available (", avail, " bytes)");
  }
}

}  // namespace interpatch
