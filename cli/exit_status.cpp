#include "exit_status.hpp"

#include <cstdio>
#include <new>
#include <utility>

#include "commands.hpp"

namespace interpatch::cli {

int exit_status(const std::exception_ptr& failure) noexcept {
  try {
    std::rethrow_exception(failure);
  } catch (const error& x) {
    return exit_status(x.code());
  } catch (const usage_error&) {
    return 2;
  } catch (const std::bad_alloc&) {
    return 5;
  } catch (...) {
    return 1;
  }
}

int fail_with(int status, std::string message) {
  for (char& c : message)
    if (c == '\n' || c == '\r') c = ' ';
  std::fprintf(stderr, "interpatch: %s\n", message.c_str());
  return status;
}

int report_failure(const std::exception_ptr& failure) {
  std::string message;
  try {
    std::rethrow_exception(failure);
  } catch (const std::bad_alloc&) {
    message = "out of memory";
  } catch (const std::exception& x) {
    message = x.what();
  } catch (...) {
    message = "unknown failure";
  }
  return fail_with(exit_status(failure), std::move(message));
}

}  // namespace interpatch::cli
