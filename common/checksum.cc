#include "common/checksum.h"

#include <array>
#include <cstdio>

namespace ratslam {
namespace {

// Slicing by 8: table[k][b] is the CRC of byte b followed by k zero bytes.
using Tables = std::array<std::array<uint32_t, 256>, 8>;

constexpr Tables MakeTables() {
  Tables t{};
  for (uint32_t b = 0; b < 256; ++b) {
    uint32_t crc = b;
    for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0x82F63B78u & (0u - (crc & 1u)));
    t[0][b] = crc;
  }
  for (uint32_t b = 0; b < 256; ++b) {
    for (int k = 1; k < 8; ++k) t[k][b] = (t[k - 1][b] >> 8) ^ t[0][t[k - 1][b] & 0xFF];
  }
  return t;
}

constexpr Tables kTables = MakeTables();

}  // namespace

uint32_t Crc32c(std::string_view bytes) {
  const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
  size_t n = bytes.size();
  uint32_t crc = 0xFFFFFFFFu;
  while (n >= 8) {
    const uint32_t lo =
        crc ^ (uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16 | uint32_t{p[3]} << 24);
    crc = kTables[7][lo & 0xFF] ^ kTables[6][(lo >> 8) & 0xFF] ^ kTables[5][(lo >> 16) & 0xFF] ^
          kTables[4][lo >> 24] ^ kTables[3][p[4]] ^ kTables[2][p[5]] ^ kTables[1][p[6]] ^
          kTables[0][p[7]];
    p += 8;
    n -= 8;
  }
  while (n-- > 0) crc = (crc >> 8) ^ kTables[0][(crc ^ *p++) & 0xFF];
  return crc ^ 0xFFFFFFFFu;
}

void AppendChecksum(std::string* bytes) {
  const uint32_t crc = Crc32c(*bytes);
  for (int i = 0; i < 4; ++i) bytes->push_back(static_cast<char>((crc >> (8 * i)) & 0xFF));
}

StatusOr<std::string_view> StripChecksum(std::string_view bytes, const std::string& source) {
  if (bytes.size() < 4) return Status::Error(source + ": truncated (no checksum)");
  const std::string_view body = bytes.substr(0, bytes.size() - 4);
  const auto* t = reinterpret_cast<const unsigned char*>(bytes.data() + body.size());
  const uint32_t stored =
      uint32_t{t[0]} | uint32_t{t[1]} << 8 | uint32_t{t[2]} << 16 | uint32_t{t[3]} << 24;
  const uint32_t computed = Crc32c(body);
  if (stored != computed) {
    char text[128];
    std::snprintf(text, sizeof text,
                  ": checksum mismatch (stored %08x, computed %08x): the file is corrupt or "
                  "truncated",
                  stored, computed);
    return Status::Error(source + text);
  }
  return body;
}

}  // namespace ratslam
