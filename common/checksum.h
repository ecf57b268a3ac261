// CRC-32C (Castagnoli) over the bytes of saved binary files, so that a flipped or lost byte is
// an error on load instead of a silently different map. The trailer is the 4-byte checksum,
// little-endian, of every byte before it.
#ifndef RATSLAM_COMMON_CHECKSUM_H_
#define RATSLAM_COMMON_CHECKSUM_H_

#include <cstdint>
#include <string>
#include <string_view>

#include "common/status.h"

namespace ratslam {

// CRC-32C of `bytes` (reflected polynomial 0x82F63B78, initial and final XOR 0xFFFFFFFF: the
// check value of "123456789" is 0xE3069283, RFC 3720 B.4).
uint32_t Crc32c(std::string_view bytes);

// Appends the CRC-32C trailer of `bytes` to them.
void AppendChecksum(std::string* bytes);

// `bytes` without their trailer when it matches; otherwise an error naming `source`.
StatusOr<std::string_view> StripChecksum(std::string_view bytes, const std::string& source);

}  // namespace ratslam

#endif  // RATSLAM_COMMON_CHECKSUM_H_
