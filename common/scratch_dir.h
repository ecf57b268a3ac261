// A fresh, uniquely named folder under the system's temporary folder (mkdtemp), removed with
// everything in it when the object goes. Tests and fuzz harnesses use it so that two checkouts
// (or two test processes) never write the same path.
#ifndef RATSLAM_COMMON_SCRATCH_DIR_H_
#define RATSLAM_COMMON_SCRATCH_DIR_H_

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

namespace ratslam {

class ScratchDir {
 public:
  // `prefix` starts the folder's name. Throws std::runtime_error when no folder can be made.
  explicit ScratchDir(const std::string& prefix = "ratslam") {
    std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw std::runtime_error("cannot create a temporary folder from " + pattern);
    }
    path_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // A path inside the folder.
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

}  // namespace ratslam

#endif  // RATSLAM_COMMON_SCRATCH_DIR_H_
