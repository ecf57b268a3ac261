#include "common/number_text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>

#include "common/random.h"

namespace ratslam {
namespace {

TEST(NumberTextTest, ShortestTextReadsBackExactly) {
  Random random(5);
  for (int i = 0; i < 100000; ++i) {
    // Magnitudes from 1e-12 to 1e12, both signs, and UTM-like coordinates.
    const double x = (random.Uniform() < 0.5 ? -1 : 1) * std::pow(10.0, random.Uniform(-12, 12)) *
                     random.Uniform(1.0, 10.0);
    const std::string text = ShortestNumber(x);
    EXPECT_EQ(std::strtod(text.c_str(), nullptr), x) << text;
  }
  // The case that cost metres: 6 significant digits of a UTM northing.
  EXPECT_EQ(std::strtod(ShortestNumber(4864951.234).c_str(), nullptr), 4864951.234);
  EXPECT_EQ(ShortestNumber(4864951.234), "4864951.234");
}

TEST(NumberTextTest, ShortestMeansNoPadding) {
  EXPECT_EQ(ShortestNumber(0.1), "0.1");
  EXPECT_EQ(ShortestNumber(2.0), "2");
  EXPECT_EQ(ShortestNumber(-0.5), "-0.5");
  EXPECT_EQ(ShortestNumber(1e-7), "1e-07");
  EXPECT_EQ(ShortestNumber(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(ShortestNumber(std::nan("")), "nan");
}

}  // namespace
}  // namespace ratslam
