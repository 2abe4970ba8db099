#include "coloc/core/number_text.hpp"

#include <gtest/gtest.h>

#include <cstdlib>

namespace coloc {
namespace {

TEST(NumberText, ReadsBackToTheBitAndStaysAsShortAsTheValueIsWritten) {
  EXPECT_EQ(exactNumberText(0.1), "0.1");
  EXPECT_EQ(exactNumberText(0.0225), "0.0225");
  EXPECT_EQ(exactNumberText(2.0), "2");
  EXPECT_EQ(exactNumberText(1e-6), "1e-06");
  for (const double v : {1.0 / 3.0, 0.000776543210987, 1e-300, -123456.789012345, 0.1 + 0.2, 6.02214076e23})
    EXPECT_EQ(std::strtod(exactNumberText(v).c_str(), nullptr), v) << exactNumberText(v);
  // More digits asked for print as %g with them, where the value takes them.
  EXPECT_EQ(exactNumberText(1e7, 10), "10000000");
  EXPECT_EQ(exactNumberText(1e7), "1e+07");
}

}  // namespace
}  // namespace coloc
