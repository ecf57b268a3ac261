#include "fuzz/fuzz_support.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace ratslam::fuzz {

std::string WriteScratchFile(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = (Scratch() / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

std::vector<std::string> SplitParts(const uint8_t* data, size_t size,
                                    const std::string& separator) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  size_t start = 0;
  for (;;) {
    const size_t at = text.find(separator, start);
    if (at == std::string::npos) {
      parts.push_back(text.substr(start));
      return parts;
    }
    parts.push_back(text.substr(start, at - start));
    start = at + separator.size();
  }
}

std::string WriteScratchFolder(const std::string& name, const std::vector<std::string>& parts,
                               const std::vector<std::string>& files) {
  const std::filesystem::path folder = Scratch() / name;
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  for (size_t i = 0; i < parts.size() && i < files.size(); ++i) {
    std::filesystem::create_directories((folder / files[i]).parent_path());
    std::ofstream(folder / files[i], std::ios::binary) << parts[i];
  }
  return folder.string();
}

void InvariantFailed(const std::string& message) {
  std::fprintf(stderr, "fuzz invariant failed: %s\n", message.c_str());
  std::abort();
}

}  // namespace ratslam::fuzz
