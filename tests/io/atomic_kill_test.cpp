// Outputs of a process killed at any moment (SIGKILL: no handler, no cleanup of its
// own) and the leftovers the library removes afterwards. The real `interpatch eval`
// is started, killed at seeded random moments and at seeded points of its writing,
// and the output's directory inspected after each kill.

#include "interpatch/io/atomic_file.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "cli_runner.hpp"
#include "temp_dir.hpp"
#include "test_util.hpp"

namespace interpatch::io {
namespace {
namespace fs = std::filesystem;

using test::read_text;
using test::TempDir;

// The library's test-only switch to the named temporary file of file systems
// without O_TMPFILE (read in src/io/atomic_file.cpp).
constexpr const char* named_switch = "INTERPATCH_TEST_NAMED_TEMP_FILE";

/// Takes the named-file path in this process for the life of the object.
class NamedTempFileGuard {
 public:
  NamedTempFileGuard() {
    if (const char* v = std::getenv(named_switch)) old_ = v;
    ::setenv(named_switch, "1", 1);
  }
  NamedTempFileGuard(const NamedTempFileGuard&) = delete;
  NamedTempFileGuard& operator=(const NamedTempFileGuard&) = delete;
  ~NamedTempFileGuard() {
    if (old_) ::setenv(named_switch, old_->c_str(), 1);
    else ::unsetenv(named_switch);
  }

 private:
  std::optional<std::string> old_;
};

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  ASSERT_TRUE(out) << p;
}

mode_t mode_of(const fs::path& p) {
  struct stat st {};
  EXPECT_EQ(::stat(p.c_str(), &st), 0) << p;
  return st.st_mode & 07777;
}

/// The leftover pattern ".<target>.interpatch-tmp.<pid>.<6 letters or digits>".
std::string leftover(const std::string& target, pid_t pid, const std::string& letters) {
  return "." + target + ".interpatch-tmp." + std::to_string(pid) + "." + letters;
}

/// Whether `name` is a file of that pattern for `target` made by `pid`.
bool is_leftover_of(const std::string& name, const std::string& target, pid_t pid) {
  const std::string prefix = leftover(target, pid, "");
  return name.size() == prefix.size() + 6 && name.compare(0, prefix.size(), prefix) == 0 &&
         std::all_of(name.begin() + static_cast<std::ptrdiff_t>(prefix.size()), name.end(),
                     [](unsigned char c) { return std::isalnum(c) != 0; });
}

/// A pid that no process has: that of a child which has exited and been reaped.
pid_t dead_pid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  int status = 0;
  EXPECT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_EQ(::kill(pid, 0), -1);
  return pid;
}

/// Whether files in `dir` can be created without a name (else the library takes
/// the named path there anyway, and tests of the unnamed one have nothing to test).
bool has_o_tmpfile(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0600);
  if (fd < 0) return false;
  ::close(fd);
  return true;
}

TEST(AtomicFileKill, UnnamedFileIsInvisibleWhileWriting) {
  TempDir dir;
  if (!has_o_tmpfile(dir.path())) GTEST_SKIP() << "the temp directory's file system has no O_TMPFILE";
  write_atomically(dir / "new.txt", [&](std::ostream& os) {
    os << std::string(3u << 20, 'n') << std::flush;  // on the disk, not only in the buffer
    EXPECT_TRUE(dir.entries().empty());
  });
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"new.txt"});
  EXPECT_EQ(read_text(dir / "new.txt"), std::string(3u << 20, 'n'));
  write_atomically(dir / "new.txt", [&](std::ostream& os) {
    os << std::string(3u << 20, 'r') << std::flush;
    EXPECT_EQ(dir.entries(), std::vector<std::string>{"new.txt"});
    EXPECT_EQ(read_text(dir / "new.txt"), std::string(3u << 20, 'n'));
  });
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"new.txt"});
  EXPECT_EQ(read_text(dir / "new.txt"), std::string(3u << 20, 'r'));
}

TEST(AtomicFileKill, NamedFallbackWritesUnderThePatternAndKeepsThePromises) {
  TempDir dir;
  NamedTempFileGuard named;
  write_text(dir / "out.txt", "old\n");
  fs::permissions(dir / "out.txt", fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  write_atomically(dir / "out.txt", [&](std::ostream& os) {
    os << "new\n" << std::flush;
    const auto names = dir.entries();
    ASSERT_EQ(names.size(), 2u);
    EXPECT_EQ(names[1], "out.txt");
    EXPECT_TRUE(is_leftover_of(names[0], "out.txt", ::getpid())) << names[0];  // the path without O_TMPFILE taken
    EXPECT_EQ(read_text(dir / names[0]), "new\n");
  });
  EXPECT_EQ(read_text(dir / "out.txt"), "new\n");
  EXPECT_EQ(mode_of(dir / "out.txt"), 0640u);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});

  // A failed writer: its named file removed, the output kept.
  EXPECT_THROW(write_atomically(dir / "out.txt",
                                [](std::ostream& os) {
                                  os << std::string(3u << 20, 'x');
                                  throw std::runtime_error("writer failed");
                                }),
               std::runtime_error);
  EXPECT_EQ(read_text(dir / "out.txt"), "new\n");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});

  // Through a symbolic link: the link kept, its target replaced.
  fs::create_symlink("out.txt", dir / "link.txt");
  write_atomically(dir / "link.txt", [](std::ostream& os) { os << "linked\n"; }, 7);
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir / "link.txt")));
  EXPECT_EQ(read_text(dir / "out.txt"), "linked\n");
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"link.txt", "out.txt"}));
}

/// Leftovers of every kind beside an output; the write removes exactly those of
/// dead processes that no one holds.
void check_stale_leftover_cleanup(bool named) {
  TempDir dir;
  std::optional<NamedTempFileGuard> guard;
  if (named) guard.emplace();
  write_text(dir / "out.npy", "old");
  const pid_t dead = dead_pid();
  const pid_t also_dead = dead_pid();
  const std::vector<std::string> stale{leftover("out.npy", dead, "AbC123"),    // this output's
                                       leftover("grid.csv", dead, "x9Y8z7")};  // another output's
  const std::vector<std::string> kept{
      leftover("out.npy", ::getpid(), "Live00"),  // a live process: ours
      leftover("out.npy", also_dead, "Lock00"),   // held by a live process whose pid is not ours to see
      ".out.npy.tmp.AbC123",                       // an older version's, without a pid
      "out.npy.interpatch-tmp." + std::to_string(dead) + ".AbC123",  // not hidden: not ours
      leftover("out.npy", dead, "AbC12"),                           // 5 letters
      leftover("out.npy", dead, "AbC123") + ".bak",                 // a suffix
      leftover("out.npy", dead, "Ab-123"),                          // not letters or digits
  };
  for (const auto& name : stale) write_text(dir / name, "partial");
  for (const auto& name : kept) write_text(dir / name, "keep");
  const std::string dir_named = leftover("out.npy", dead, "Dir000");  // a directory: not a file of ours
  fs::create_directory(dir / dir_named);
  const int held = ::open((dir / kept[1]).c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(held, 0);
  ASSERT_EQ(::flock(held, LOCK_EX | LOCK_NB), 0);

  write_atomically(dir / "out.npy", [&](std::ostream& os) {
    // Removed before the writing starts: their space is free for the new output.
    for (const auto& name : stale) EXPECT_FALSE(fs::exists(dir / name)) << name;
    os << "new";
  });
  ::close(held);

  std::vector<std::string> expected = kept;
  expected.push_back(dir_named);
  expected.push_back("out.npy");
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(dir.entries(), expected);
  EXPECT_EQ(read_text(dir / "out.npy"), "new");
  for (const auto& name : kept) EXPECT_EQ(read_text(dir / name), "keep") << name;

  // Once nobody holds it, the leftover of the dead pid goes with the next write.
  write_atomically(dir / "other.txt", [](std::ostream& os) { os << "x"; });
  EXPECT_FALSE(fs::exists(dir / kept[1]));
  EXPECT_TRUE(fs::exists(dir / kept[0]));
}

TEST(AtomicFileKill, NamedFallbackRemovesStaleLeftoversOfDeadProcessesOnly) { check_stale_leftover_cleanup(true); }

TEST(AtomicFileKill, UnnamedPathRemovesStaleLeftoversOfDeadProcessesOnly) { check_stale_leftover_cleanup(false); }

#ifdef INTERPATCH_CLI

/// The environment of this process with `overrides` ("NAME=value") in place.
std::vector<std::string> environment_with(const std::vector<std::string>& overrides) {
  std::vector<std::string> env;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string var = *e;
    const bool overridden = std::any_of(overrides.begin(), overrides.end(), [&](const std::string& o) {
      return var.compare(0, o.find('=') + 1, o, 0, o.find('=') + 1) == 0;
    });
    if (!overridden) env.push_back(var);
  }
  env.insert(env.end(), overrides.begin(), overrides.end());
  return env;
}

/// Starts the interpatch command (standard input and output /dev/null, standard
/// error into `err`) without waiting for it.
pid_t spawn_cli(const std::vector<std::string>& args, const std::vector<std::string>& env, const fs::path& err) {
  std::vector<std::string> argv_s{INTERPATCH_CLI};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_s = env;
  std::vector<char*> envp;
  for (auto& e : env_s) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = -1;
  const int r = ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (r != 0) throw std::runtime_error("cannot start " + argv_s[0] + ": " + std::strerror(r));
  return pid;
}

/// The file offset of the file `pid` has open in `dir` (the unnamed file shows as
/// "dir/#inode (deleted)", the named one by its name), that is the bytes written so
/// far; -1 while it has none open.
long long bytes_written_in(pid_t pid, const fs::path& dir) {
  const std::string fds = "/proc/" + std::to_string(pid) + "/fd";
  const std::string prefix = dir.string() + "/";
  DIR* d = ::opendir(fds.c_str());
  if (d == nullptr) return -1;
  long long pos = -1;
  while (const dirent* e = ::readdir(d)) {
    char target[4096];
    const ssize_t n = ::readlinkat(::dirfd(d), e->d_name, target, sizeof target - 1);
    if (n <= 0 || std::string(target, static_cast<std::size_t>(n)).rfind(prefix, 0) != 0) continue;
    std::ifstream info("/proc/" + std::to_string(pid) + "/fdinfo/" + e->d_name);
    std::string key;
    long long value = -1;
    while (info >> key >> value)
      if (key == "pos:") {
        pos = value;
        break;
      }
    break;
  }
  ::closedir(d);
  return pos;
}

struct KillCounts {
  int mid_write = 0, old_kept = 0, new_in_place = 0, finished = 0, leftovers = 0;
};

/// Runs `interpatch eval terrain.json --grid <grid> -o <output>` `kills` times into a
/// directory holding a good older output, killing each run with SIGKILL: at once,
/// after a seeded random delay (up to a little more than a whole run), or when its
/// file has reached a seeded random size (its first byte, anywhere, near the end;
/// stopped there first, so that a kill before the file is complete is known to be
/// one). After each kill the directory must hold the old output byte for byte or
/// the complete new one, and nothing else; killed before its file was complete,
/// the old one. The only exception is the one designed
/// in: a leftover of the killed run under the pattern (the whole write long on the
/// named path; on the unnamed path only the two system calls between link and
/// rename, so complete and with the old output still in place), which the next
/// write into the directory must remove.
void kill_repeatedly(const std::string& output, const std::string& grid, const std::string& old_grid, int kills,
                     unsigned seed, bool named) {
  const fs::path spec = fs::path(INTERPATCH_EXAMPLES) / "terrain.json";
  const std::vector<std::string> env = environment_with({std::string(named_switch) + (named ? "=1" : "=0")});
  KillCounts counts;

  // The complete new output, an older one to protect, and how long a run takes
  // (only to spread the kills over it: no check depends on time).
  TempDir ref;
  auto r = test::run_cli(ref.path(), {"eval", spec.string(), "--grid", grid, "-o", (ref / output).string()}, env);
  EXPECT_EQ(r.status, 0) << r.err;
  const std::string fresh = read_text(ref / output);
  const double run_seconds = r.seconds;
  r = test::run_cli(ref.path(), {"eval", spec.string(), "--grid", old_grid, "-o", (ref / ("old-" + output)).string()},
                    env);
  EXPECT_EQ(r.status, 0) << r.err;
  const std::string old = read_text(ref / ("old-" + output));
  EXPECT_TRUE(!fresh.empty() && !old.empty() && fresh != old);
  if (fresh.empty() || old.empty() || fresh == old) return;
  TempDir dir;
  TempDir logs;
  const fs::path out = dir / output;
  write_text(out, old);
  fs::permissions(out, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  auto g = test::rng(seed);
  for (int k = 0; k < kills; ++k) {
    SCOPED_TRACE("kill " + std::to_string(k) + (named ? " (named file)" : ""));
    const pid_t pid = spawn_cli({"eval", spec.string(), "--grid", grid, "-o", out.string()}, env, logs / "err");
    bool reaped = false;
    int status = 0;
    long long seen = -1;  // the bytes written when it was stopped and killed, if it had its file open
    if (k == 0) {
      ::kill(pid, SIGKILL);  // very early: the moment it has started
    } else if (k % 2 == 1) {
      const double fraction = k == 1 ? 0.002 : test::uniform(g, 0.0, 1.2);
      std::this_thread::sleep_for(std::chrono::duration<double>(fraction * run_seconds));
      ::kill(pid, SIGKILL);
    } else {
      // When the file reaches a size: its first byte, anywhere, near the end.
      const auto size = static_cast<double>(fresh.size());
      const double at = k == 2            ? 1.0
                        : k >= kills - 6    ? test::uniform(g, 0.97, 1.0) * size
                                            : test::uniform(g, 0.0, 1.0) * size;
      for (;;) {
        const pid_t w = ::waitpid(pid, &status, WNOHANG);
        if (w == pid) {
          reaped = true;
          break;
        }
        const long long now = bytes_written_in(pid, dir.path());
        if (now >= 0 && static_cast<double>(now) >= at) {
          // Stopped first, it writes no more while it is looked at: how far it got
          // is then known exactly, however late this process sends the kill.
          ::kill(pid, SIGSTOP);
          if (::waitpid(pid, &status, WUNTRACED) != pid || !WIFSTOPPED(status)) {
            reaped = true;  // it finished first
            break;
          }
          seen = bytes_written_in(pid, dir.path());
          ::kill(pid, SIGKILL);
          break;
        }
        std::this_thread::sleep_for(std::chrono::microseconds(50));
      }
    }
    if (!reaped) {
      EXPECT_EQ(::waitpid(pid, &status, 0), pid);
    }
    if (WIFEXITED(status)) {
      EXPECT_EQ(WEXITSTATUS(status), 0) << read_text(logs / "err");
      ++counts.finished;
    } else {
      EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << status;
    }

    // What the directory holds.
    const std::vector<std::string> names = dir.entries();
    std::vector<std::string> others;
    for (const auto& n : names)
      if (n != output) others.push_back(n);
    EXPECT_TRUE(std::find(names.begin(), names.end(), output) != names.end()) << "the output is gone";
    const std::string now = read_text(out);
    const bool is_old = now == old, is_new = now == fresh;
    EXPECT_TRUE(is_old || is_new) << "the output is neither the old one nor the new one: " << now.size() << " bytes";
    if (is_new) {
      EXPECT_EQ(mode_of(out), 0640u);  // the replaced file's permissions
    }
    counts.old_kept += is_old;
    counts.new_in_place += is_new;
    if (seen >= 0 && seen < static_cast<long long>(fresh.size())) {
      ++counts.mid_write;
      EXPECT_TRUE(is_old) << "killed at " << seen << " of " << fresh.size() << " bytes, yet the output changed";
      if (named) {
        EXPECT_EQ(others.size(), 1u) << "killed while writing, yet no named file";
      } else {
        EXPECT_TRUE(others.empty());
      }
    }

    if (!others.empty()) {
      ++counts.leftovers;
      EXPECT_EQ(others.size(), 1u);
      for (const auto& n : others) {
        EXPECT_TRUE(is_leftover_of(n, output, pid)) << "'" << n << "' is left behind";
        if (!named) {
          // Only the window between link and rename: the complete new file, the old
          // output in place.
          EXPECT_TRUE(is_old);
          EXPECT_TRUE(read_text(dir / n) == fresh) << n;
        }
      }
      // The next write into the directory removes it.
      write_atomically(dir / "next.txt", [](std::ostream& os) { os << "next"; });
      EXPECT_EQ(dir.entries(), (std::vector<std::string>{"next.txt", output}));
      fs::remove(dir / "next.txt");
    }
    if (!is_old) write_text(out, old);  // keeps the replaced file's permissions
    if (::testing::Test::HasFatalFailure()) break;
  }
  std::cout << "[ kills    ] " << output << (named ? " (named file)" : "") << ": " << kills << " kills, "
            << counts.finished << " runs finished first, " << counts.mid_write << " seen mid-write, "
            << counts.old_kept << " left the old output, " << counts.new_in_place << " the new one, "
            << counts.leftovers << " a leftover (removed by the next write); a run takes " << run_seconds << " s\n";
}

TEST(AtomicFileKill, KilledEvalToNpyLeavesTheOldOrTheNewOutputAndNothingElse) {
  if (!has_o_tmpfile(fs::temp_directory_path())) GTEST_SKIP() << "the temp directory's file system has no O_TMPFILE";
  kill_repeatedly("out.npy", "1500", "700", 32, 1, false);
}

TEST(AtomicFileKill, KilledEvalToCsvLeavesTheOldOrTheNewOutputAndNothingElse) {
  if (!has_o_tmpfile(fs::temp_directory_path())) GTEST_SKIP() << "the temp directory's file system has no O_TMPFILE";
  kill_repeatedly("out.csv", "500", "300", 20, 2, false);
}

TEST(AtomicFileKill, KilledEvalOnTheNamedFallbackLeavesALeftoverTheNextWriteRemoves) {
  kill_repeatedly("out.npy", "1500", "700", 20, 3, true);
}

#endif  // INTERPATCH_CLI

}  // namespace
}  // namespace interpatch::io
