#pragma once
// Running the real `interpatch` command from a test: its exit status, both streams,
// the wall time and the peak memory of that one process.

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <system_error>
#include <vector>

#include "temp_dir.hpp"

extern char** environ;

namespace interpatch::test {

struct CliResult {
  int status = -1;  ///< the exit status; 128 + the signal when killed by one
  std::string out, err;
  double seconds = 0;
  long max_rss_kb = 0;  ///< peak resident memory of the command
};

/// Runs `exe args...` in `cwd` with standard input from /dev/null, the environment of
/// this process plus `env` ("NAME=value", overriding).
inline CliResult run_program(const std::string& exe, const std::filesystem::path& cwd,
                             const std::vector<std::string>& args, const std::vector<std::string>& env = {}) {
  static std::atomic<int> counter{0};
  const std::filesystem::path capture = std::filesystem::temp_directory_path() /
      ("interpatch-capture-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::create_directories(capture);
  const std::string out_file = (capture / "out").string(), err_file = (capture / "err").string();
  const std::string dir = cwd.string();

  // Everything the child needs is built before fork: after it, only exec-safe calls.
  std::vector<std::string> argv_s{exe};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_s;
  for (char** e = environ; *e; ++e) {
    const std::string var = *e;
    const bool overridden = std::any_of(env.begin(), env.end(), [&](const std::string& o) {
      const auto eq = o.find('=');
      return var.compare(0, eq + 1, o, 0, eq + 1) == 0;
    });
    if (!overridden) env_s.push_back(var);
  }
  env_s.insert(env_s.end(), env.begin(), env.end());
  std::vector<char*> envp;
  for (auto& e : env_s) envp.push_back(e.data());
  envp.push_back(nullptr);

  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(out_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || err < 0 || ::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(err, 2) < 0 ||
        ::chdir(dir.c_str()) != 0)
      ::_exit(126);
    ::execve(argv[0], argv.data(), envp.data());
    ::_exit(127);
  }
  CliResult r;
  int wstatus = 0;
  rusage usage{};
  if (pid < 0 || ::wait4(pid, &wstatus, 0, &usage) != pid) {
    ADD_FAILURE() << "could not run " << exe;
  } else {
    r.status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
    r.max_rss_kb = usage.ru_maxrss;
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.out = read_text(out_file);
  r.err = read_text(err_file);
  std::error_code ec;
  std::filesystem::remove_all(capture, ec);
  return r;
}

#ifdef INTERPATCH_CLI
/// The interpatch command built with the tests.
inline CliResult run_cli(const std::filesystem::path& cwd, const std::vector<std::string>& args,
                         const std::vector<std::string>& env = {}) {
  return run_program(INTERPATCH_CLI, cwd, args, env);
}
#endif

/// A failure as the command reports it: the status, nothing on stdout, and exactly one
/// line "interpatch: ..." on stderr containing every fragment.
inline void expect_one_line_error(const CliResult& r, int status, std::initializer_list<std::string> fragments) {
  EXPECT_EQ(r.status, status) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("interpatch: ", 0), 0u) << r.err;
  EXPECT_TRUE(!r.err.empty() && r.err.back() == '\n') << r.err;
  for (const auto& f : fragments) EXPECT_NE(r.err.find(f), std::string::npos) << "'" << r.err << "' lacks '" << f << "'";
}

}  // namespace interpatch::test
