#pragma once
// A scratch directory per test, removed with its contents.

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace interpatch::test {

/// A fresh directory under the system temp directory, removed with its contents
/// (made writable first, for tests that take permissions away).
class TempDir {
 public:
  // mkdtemp: a directory that did not exist before, even when a process that had
  // this one's pid left its directory behind.
  TempDir() {
    std::string templ = (std::filesystem::temp_directory_path() / "interpatch-test-XXXXXX").string();
    if (::mkdtemp(templ.data()) == nullptr)
      throw std::filesystem::filesystem_error("mkdtemp", templ, std::error_code(errno, std::generic_category()));
    path_ = templ;
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all, std::filesystem::perm_options::add, ec);
    std::filesystem::remove_all(path_, ec);
  }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  /// Names of everything in the directory (temporary files included), sorted.
  [[nodiscard]] std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(path_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
  [[nodiscard]] std::size_t count() const { return entries().size(); }

 private:
  std::filesystem::path path_;
};

/// The whole content of a file, bytes as they are.
inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Writes the bytes as they are, replacing the file.
inline void write_bytes(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace interpatch::test
