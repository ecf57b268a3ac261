#include "common/provenance.h"

#include <ctime>
#include <filesystem>
#include <system_error>

namespace ratslam {

std::string RunProvenance::Recorded(const std::string& path) const {
  if (staging_folder.empty() || path.compare(0, staging_folder.size(), staging_folder) != 0) {
    return path;
  }
  const std::string rest = path.substr(staging_folder.size());
  if (!rest.empty() && rest.front() != '/') return path;
  return output_folder + rest;
}

std::vector<InputDescription> DescribeInputs(const std::vector<std::string>& paths) {
  namespace fs = std::filesystem;
  std::vector<InputDescription> out;
  for (const std::string& path : paths) {
    InputDescription d;
    d.path = path;
    std::error_code ec;
    if (fs::is_regular_file(path, ec)) {
      const uintmax_t size = fs::file_size(path, ec);
      if (!ec) {
        d.bytes = size;
        d.files = 1;
      }
    } else if (fs::is_directory(path, ec)) {
      for (fs::recursive_directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec)) {
        std::error_code file_ec;
        if (!it->is_regular_file(file_ec) || file_ec) continue;
        const uintmax_t size = it->file_size(file_ec);
        if (file_ec) continue;
        d.bytes += size;
        ++d.files;
      }
    }
    out.push_back(std::move(d));
  }
  return out;
}

std::string UtcNowIso8601() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  if (gmtime_r(&now, &utc) == nullptr) return "";
  char text[32];
  if (std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc) == 0) return "";
  return text;
}

std::string ShellCommandLine(int argc, const char* const* argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i] ? argv[i] : "";
    bool plain = !a.empty();
    for (char c : a) {
      const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      std::string("-_./=:,+@%").find(c) != std::string::npos;
      plain = plain && ok;
    }
    if (i > 0) line += ' ';
    if (plain) {
      line += a;
    } else {
      line += '\'';
      for (char c : a) line += c == '\'' ? std::string("'\\''") : std::string(1, c);
      line += '\'';
    }
  }
  return line;
}

}  // namespace ratslam
