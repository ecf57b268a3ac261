#include "common/text_file.h"

#include <filesystem>
#include <sstream>
#include <system_error>

namespace ratslam {

Status OpenRegularFile(const std::string& path, const std::string& what, std::ifstream* in) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(status)) {
    return Status::Error(path + ": cannot open " + what + " (no such file)");
  }
  if (!std::filesystem::is_regular_file(status)) {
    return Status::Error(path + ": " + what + " is not a regular file");
  }
  in->open(path, std::ios::binary);
  if (!*in) return Status::Error(path + ": cannot open " + what);
  return Status::Ok();
}

StatusOr<std::string> ReadRegularFile(const std::string& path, const std::string& what,
                                      size_t max_bytes) {
  std::ifstream in;
  RATSLAM_RETURN_IF_ERROR(OpenRegularFile(path, what, &in));
  std::string bytes;
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    bytes.append(buffer, static_cast<size_t>(in.gcount()));
    if (bytes.size() > max_bytes) {
      return Status::Error(path + ": " + what + " is larger than " + std::to_string(max_bytes) +
                           " bytes");
    }
  }
  if (in.bad()) return Status::Error(path + ": read error in " + what);
  return bytes;
}

LineResult ReadLine(std::istream& in, std::string* line, size_t max_bytes) {
  line->clear();
  std::streambuf* buffer = in.rdbuf();
  if (buffer == nullptr || !in.good()) return LineResult::kEnd;
  bool any = false;
  for (;;) {
    const int c = buffer->sbumpc();
    if (c == std::char_traits<char>::eof()) {
      in.setstate(std::ios::eofbit);
      return any ? LineResult::kLine : LineResult::kEnd;
    }
    any = true;
    if (c == '\n') return LineResult::kLine;
    if (line->size() >= max_bytes) return LineResult::kTooLong;
    line->push_back(static_cast<char>(c));
  }
}

}  // namespace ratslam
