// Opening untrusted input files: only regular files (a manifest naming /dev/zero or a FIFO must not
// make a reader wait or grow without end), read in lines of bounded length, and whole files of
// bounded size.
#ifndef RATSLAM_COMMON_TEXT_FILE_H_
#define RATSLAM_COMMON_TEXT_FILE_H_

#include <cstddef>
#include <fstream>
#include <istream>
#include <string>

#include "common/status.h"

namespace ratslam {

// Longest line any of our text readers accepts (a Wi-Fi line of a phone log is ~100 bytes).
inline constexpr size_t kMaxLineBytes = 1 << 20;

// Opens `path` for reading; fails (naming `what` and the path) when it does not exist, is not a
// regular file (folder, device, FIFO, socket), or cannot be opened.
Status OpenRegularFile(const std::string& path, const std::string& what, std::ifstream* in);

// The whole of a regular file of at most `max_bytes`.
StatusOr<std::string> ReadRegularFile(const std::string& path, const std::string& what,
                                      size_t max_bytes);

enum class LineResult { kLine, kEnd, kTooLong };
// std::getline with a bound: reads the next line (without its '\n') into *line, or says the
// input ended, or that the line is longer than `max_bytes` (the stream is then left mid-line).
LineResult ReadLine(std::istream& in, std::string* line, size_t max_bytes = kMaxLineBytes);

}  // namespace ratslam

#endif  // RATSLAM_COMMON_TEXT_FILE_H_
