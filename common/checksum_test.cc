#include "common/checksum.h"

#include <gtest/gtest.h>

#include <string>

namespace ratslam {
namespace {

// Published check values: RFC 3720 appendix B.4 and the CRC catalogue's "check" for CRC-32C.
TEST(ChecksumTest, KnownValues) {
  EXPECT_EQ(Crc32c("123456789"), 0xE3069283u);
  EXPECT_EQ(Crc32c(""), 0x00000000u);
  EXPECT_EQ(Crc32c(std::string(32, '\0')), 0x8A9136AAu);
  EXPECT_EQ(Crc32c(std::string(32, '\xFF')), 0x62A8AB43u);
  std::string ascending;
  for (int i = 0; i < 32; ++i) ascending.push_back(static_cast<char>(i));
  EXPECT_EQ(Crc32c(ascending), 0x46DD794Eu);
}

// The 8-byte path and the byte-at-a-time tail agree with each other at every length and offset.
TEST(ChecksumTest, EveryLengthAgreesWithTheBytewiseDefinition) {
  std::string bytes;
  for (int i = 0; i < 100; ++i) bytes.push_back(static_cast<char>(i * 37 + 11));
  for (size_t len = 0; len <= bytes.size(); ++len) {
    uint32_t crc = 0xFFFFFFFFu;
    for (size_t i = 0; i < len; ++i) {
      crc ^= static_cast<unsigned char>(bytes[i]);
      for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0x82F63B78u & (0u - (crc & 1u)));
    }
    EXPECT_EQ(Crc32c(std::string_view(bytes).substr(0, len)), crc ^ 0xFFFFFFFFu) << len;
  }
}

TEST(ChecksumTest, EverySingleByteChangeIsCaught) {
  std::string file = "a saved map's bytes, long enough to cross the 8-byte path";
  AppendChecksum(&file);
  ASSERT_TRUE(StripChecksum(file, "m").ok());
  EXPECT_EQ(*StripChecksum(file, "m"), file.substr(0, file.size() - 4));
  for (size_t i = 0; i < file.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      std::string flipped = file;
      flipped[i] = static_cast<char>(flipped[i] ^ (1 << bit));
      const StatusOr<std::string_view> r = StripChecksum(flipped, "m.map");
      ASSERT_FALSE(r.ok()) << i << " " << bit;
      EXPECT_NE(r.status().message().find("m.map: checksum mismatch"), std::string::npos);
    }
  }
  EXPECT_FALSE(StripChecksum(file.substr(0, file.size() - 1), "m").ok());
  EXPECT_FALSE(StripChecksum("abc", "m").ok());
}

}  // namespace
}  // namespace ratslam
