// A string as a TOML basic string literal that every TOML reader gives back unchanged: quotes and
// backslashes escaped, and control characters (which TOML forbids raw) as \uXXXX. Shared by every
// printer of TOML (configs, world files, data-set manifests).
#ifndef RATSLAM_COMMON_TOML_STRING_H_
#define RATSLAM_COMMON_TOML_STRING_H_

#include <cstdio>
#include <string>

namespace ratslam {

inline std::string TomlQuoted(const std::string& text) {
  std::string out(1, '"');  // appended piecewise: GCC 12 warns falsely on "\"" + s
  for (unsigned char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20 || c == 0x7f) {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\u%04x", static_cast<unsigned>(c));
      out += buffer;
    } else {
      out += static_cast<char>(c);
    }
  }
  out += '"';
  return out;
}

}  // namespace ratslam

#endif  // RATSLAM_COMMON_TOML_STRING_H_
