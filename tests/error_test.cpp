#include "interpatch/error.hpp"

#include <set>
#include <string>

#include "linalg/collocation.hpp"
#include "test_util.hpp"

namespace interpatch {
namespace {

constexpr errc kAll[] = {
    errc::invalid_json,   errc::missing_field,  errc::wrong_type,         errc::unknown_type,     errc::not_finite,
    errc::ragged_grid,    errc::too_few_points, errc::invalid_degree,     errc::zero_chord,       errc::non_increasing,
    errc::invalid_knots,  errc::invalid_weight, errc::size_mismatch,      errc::out_of_domain,    errc::singular,
    errc::corner_gap,     errc::network_gap,    errc::incompatible_twist, errc::tangent_mismatch, errc::invalid_blend,
    errc::no_exact_form,  errc::malformed_file, errc::closing_gap, errc::tolerance_not_met, errc::ill_conditioned, errc::invalid_grading, errc::block_mismatch, errc::network_order,       errc::file_unreadable,  errc::file_unwritable,
    errc::too_large,
    errc::internal};

TEST(Error, EveryCodeHasItsOwnName) {
  std::set<std::string> names;
  for (errc c : kAll) {
    const std::string n(to_string(c));
    EXPECT_FALSE(n.empty());
    EXPECT_TRUE(names.insert(n).second) << "two codes are called " << n;
  }
  EXPECT_EQ(to_string(errc::zero_chord), "zero_chord");
  EXPECT_EQ(to_string(errc::no_exact_form), "no_exact_form");
}

TEST(Error, CarriesCodeAndMessage) {
  const error e(errc::corner_gap, "corner p11: gap 0.5");
  EXPECT_EQ(e.code(), errc::corner_gap);
  EXPECT_STREQ(e.what(), "corner p11: gap 0.5");
}

TEST(Error, SingularCollocationNamesTheRow) {
  // Five cubic basis functions on [0, 1] with a knot at 0.5, but every parameter in
  // (0.6, 1]: the Schoenberg–Whitney condition fails for the first functions.
  const KnotVector k(3, {0, 0, 0, 0, 0.5, 1, 1, 1, 1});
  const std::vector<double> t{0.6, 0.7, 0.8, 0.9, 1.0};
  EXPECT_ERRC((void)detail::factor_collocation(k, t), singular, "singular at row");
}

}  // namespace
}  // namespace interpatch
