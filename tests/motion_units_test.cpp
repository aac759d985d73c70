// The time and velocity units added for `uphill simulate` (src/io/units.*).
#include <gtest/gtest.h>

#include "io/units.hpp"
#include "model/input_error.hpp"

namespace uphill::testing {
namespace {

TEST(MotionUnits, TimeAndVelocityToSI) {
  EXPECT_DOUBLE_EQ(ParseQuantity("250ms", Dimension::kTime, "t"), 0.25);
  EXPECT_DOUBLE_EQ(ParseQuantity("1.5 s", Dimension::kTime, "t"), 1.5);
  EXPECT_DOUBLE_EQ(ParseQuantity("2min", Dimension::kTime, "t"), 120.0);
  EXPECT_DOUBLE_EQ(ParseQuantity("0.1m/s", Dimension::kVelocity, "v0"), 0.1);
  EXPECT_DOUBLE_EQ(ParseQuantity("-25mm/s", Dimension::kVelocity, "v0"), -0.025);
  EXPECT_EQ(AcceptedUnits(Dimension::kTime), "s, ms");
  EXPECT_EQ(AcceptedUnits(Dimension::kVelocity), "m/s, mm/s, cm/s");
  EXPECT_THROW(ParseQuantity("1", Dimension::kTime, "t"), InputError);
  EXPECT_THROW(ParseQuantity("1mm", Dimension::kTime, "t"), InputError);
  EXPECT_THROW(ParseQuantity("1s", Dimension::kLength, "x"), InputError);
  EXPECT_EQ(ToUnit(0.25, Dimension::kTime, "ms"), 250.0);
  EXPECT_EQ(SplitUnitSuffix("t_s"), (std::pair<std::string, std::string>{"t", "s"}));
}

}  // namespace
}  // namespace uphill::testing
