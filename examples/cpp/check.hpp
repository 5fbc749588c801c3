#pragma once
// What the example programs use to check the claims their snippets make in
// comments ("// (1, 1, 0)", "// == q(3, 5) up to rounding"): a claim that does not
// hold throws claim_failed naming the claim and what came out, and run() turns
// that, or any other exception, into a message on stderr and exit status 1, so
// that ctest reports a snippet whose comment has become false.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>
#include <string_view>

#include <interpatch/error.hpp>
#include <interpatch/vec3.hpp>

namespace example {

class claim_failed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline std::string str(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

inline std::string str(const interpatch::Vec3& p) { return "(" + str(p.x) + ", " + str(p.y) + ", " + str(p.z) + ")"; }

/// The claim holds.
inline void expect(bool holds, std::string_view claim) {
  if (!holds) throw claim_failed(std::string(claim));
}

/// `got` is `want` to rounding: within `tol` times the size of `want` (at least 1),
/// since the library promises its results to rounding relative to the data's size.
inline void expect_near(double got, double want, std::string_view claim, double tol = 1e-12) {
  if (!(std::abs(got - want) <= tol * std::max(1.0, std::abs(want))))
    throw claim_failed(std::string(claim) + ": got " + str(got) + ", expected " + str(want));
}

inline void expect_near(const interpatch::Vec3& got, const interpatch::Vec3& want, std::string_view claim,
                        double tol = 1e-12) {
  if (!(interpatch::distance(got, want) <= tol * std::max(1.0, interpatch::norm(want))))
    throw claim_failed(std::string(claim) + ": got " + str(got) + ", expected " + str(want));
}

/// Runs an example's body: 0 when every claim held, 1 with a message otherwise.
template <class Body>
int run(std::string_view name, Body&& body) {
  const std::string n(name);
  try {
    body();
    std::printf("%s: every claim holds\n", n.c_str());
    return 0;
  } catch (const claim_failed& e) {
    std::fprintf(stderr, "%s: claim failed: %s\n", n.c_str(), e.what());
  } catch (const interpatch::error& e) {
    const std::string code(interpatch::to_string(e.code()));
    std::fprintf(stderr, "%s: interpatch::error %s: %s\n", n.c_str(), code.c_str(), e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", n.c_str(), e.what());
  }
  return 1;
}

}  // namespace example
