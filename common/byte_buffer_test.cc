#include "common/byte_buffer.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "common/status.h"

namespace ratslam {
namespace {

// The byte order is fixed: little-endian whatever the host, checked against hand-written bytes.
TEST(ByteBufferTest, NumbersAreLittleEndian) {
  ByteWriter w;
  w.Pod<uint32_t>(0x01020304u);
  w.Pod<int16_t>(-2);
  w.Pod<double>(1.0);  // IEEE 754: 0x3FF0000000000000
  const std::string expected("\x04\x03\x02\x01\xFE\xFF\0\0\0\0\0\0\xF0\x3F", 14);
  EXPECT_EQ(w.bytes(), expected);
  ByteReader r(w.bytes(), "test");
  uint32_t a = 0;
  int16_t b = 0;
  double c = 0;
  ASSERT_TRUE(r.Pod(&a) && r.Pod(&b) && r.Pod(&c));
  EXPECT_EQ(a, 0x01020304u);
  EXPECT_EQ(b, -2);
  EXPECT_EQ(c, 1.0);
  EXPECT_TRUE(r.AtEnd());
}

TEST(ByteBufferTest, CountsBeyondTheBytesLeftFailBeforeAllocating) {
  ByteWriter w;
  w.Count(std::numeric_limits<uint64_t>::max() / 8);
  ByteReader r(w.bytes(), "f.bin");
  std::vector<double> v;
  EXPECT_FALSE(r.PodVector(&v));
  EXPECT_TRUE(v.empty());
  EXPECT_EQ(r.error().rfind("f.bin at byte 8: count", 0), 0u) << r.error();
}

TEST(StatusOrTest, ValueOfAnErrorThrowsWithTheMessage) {
  StatusOr<int> error = Status::Error("no such file");
  EXPECT_THROW((void)error.value(), std::logic_error);
  try {
    (void)*error;
  } catch (const std::logic_error& e) {
    EXPECT_NE(std::string(e.what()).find("no such file"), std::string::npos);
  }
  StatusOr<int> fine = 3;
  EXPECT_EQ(fine.value(), 3);
}

}  // namespace
}  // namespace ratslam
