#include "common/status.h"

#include <gtest/gtest.h>

#include <string>

namespace ratslam {
namespace {

StatusOr<int> Half(int n) {
  if (n % 2 != 0) return Status::Error(std::to_string(n) + " is odd");
  return n / 2;
}

TEST(StatusOrTest, HoldsAValueOrAnError) {
  const StatusOr<int> four = Half(8);
  ASSERT_TRUE(four.ok());
  EXPECT_EQ(*four, 4);
  const StatusOr<int> odd = Half(3);
  EXPECT_FALSE(odd.ok());
  EXPECT_EQ(odd.status().message(), "3 is odd");
  EXPECT_THROW(odd.value(), std::logic_error);  // a programming mistake, defined behaviour
}

// An OK status holds no value: a StatusOr made from one reports an error instead of "ok" with
// nothing inside (which value() would then throw on far from the mistake).
TEST(StatusOrTest, AnOkStatusWithoutAValueIsAnError) {
  const StatusOr<std::string> made = Status::Ok();
  EXPECT_FALSE(made.ok());
  EXPECT_EQ(made.status().message(), StatusOr<std::string>::kOkWithoutValue);
  EXPECT_THROW(made.value(), std::logic_error);
}

TEST(StatusTest, ContextIsPrependedToErrorsOnly) {
  EXPECT_EQ(Status::Error("bad").WithContext("file.csv:3").message(), "file.csv:3: bad");
  EXPECT_TRUE(Status::Ok().WithContext("file.csv:3").ok());
}

}  // namespace
}  // namespace ratslam
