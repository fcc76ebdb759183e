// The one check of a number a user gives (core/number_range.h): the flags'
// validator and the Python module's arguments both go through it, so NaN and
// the infinities, which comparisons alone let through, are refused
// everywhere, with the name and the range in the message.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/number_range.h"
#include "test_util.h"

namespace lo {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(NumberRange, NanAndInfinitiesAreInNoRange) {
  for (const NumberRange& range : {kFiniteNumber, kPositiveNumber, NumberRange{-30, 30},
                                   NumberRange{1, 12, false, true}, NumberRange{0, 2, true}}) {
    SCOPED_TRACE(range.ToString());
    EXPECT_FALSE(range.contains(kNan));
    EXPECT_FALSE(range.contains(kInf));
    EXPECT_FALSE(range.contains(-kInf));
    EXPECT_FALSE(range.contains(std::numeric_limits<double>::signaling_NaN()));
  }
  // What a comparison-only check (CLI::Range) does with NaN: it passes.
  EXPECT_FALSE(kNan < -30 || kNan > 30);
}

TEST(NumberRange, BoundsAreClosedUnlessAboveMin) {
  const NumberRange target{1e-3, 1.0};
  EXPECT_TRUE(target.contains(1e-3));
  EXPECT_TRUE(target.contains(1.0));
  EXPECT_FALSE(target.contains(1e-9));
  EXPECT_FALSE(target.contains(std::nextafter(1.0, 2.0)));
  EXPECT_FALSE(target.contains(-1));
  EXPECT_FALSE(kPositiveNumber.contains(0.0));
  EXPECT_FALSE(kPositiveNumber.contains(-0.0));
  EXPECT_TRUE(kPositiveNumber.contains(std::numeric_limits<double>::denorm_min()));
  EXPECT_TRUE(kPositiveNumber.contains(std::numeric_limits<double>::max()));
  EXPECT_TRUE(kFiniteNumber.contains(-std::numeric_limits<double>::max()));
  const NumberRange depth{1, 12, false, true};
  EXPECT_TRUE(depth.contains(12));
  EXPECT_FALSE(depth.contains(6.5));
  EXPECT_FALSE(depth.contains(0));
  EXPECT_FALSE(depth.contains(13));
}

TEST(NumberRange, TheMessageNamesTheSettingTheRangeAndTheValue) {
  EXPECT_EQ(NumberRange({1e-3, 1.0}).ToString(), "a finite number from 0.001 to 1");
  EXPECT_EQ(kPositiveNumber.ToString(), "a finite number > 0");
  EXPECT_EQ(kFiniteNumber.ToString(), "a finite number");
  EXPECT_EQ(NumberRange({0, 2, true}).ToString(), "a finite number > 0 and <= 2");
  EXPECT_EQ(NumberRange({1, 2e8, false, true}).ToString(), "a whole number from 1 to 200000000");
  EXPECT_EQ(numberRangeError(0.5, {0, 1}), "");
  EXPECT_EQ(numberRangeError(kNan, {1e-3, 1.0}),
            "must be a finite number from 0.001 to 1, got nan");
  test::expectRefusal([] { checkNumber(-kInf, kPositiveNumber, "target_error"); },
                      {"target_error: must be a finite number > 0, got -inf"});
  test::expectRefusal(
      [] {
        checkNumber(-1, {1, 12, false, true}, "depth");
      },
      {"depth: must be a whole number from 1 to 12, got -1"});
  EXPECT_EQ(checkNumber(0.25, {0, 1}, "tolerance"), 0.25);
}

}  // namespace
}  // namespace lo
