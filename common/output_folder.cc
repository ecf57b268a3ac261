#include "common/output_folder.h"

#include <filesystem>
#include <system_error>

#include "common/file_util.h"

namespace ratslam {

StatusOr<std::unique_ptr<DiskFolder>> DiskFolder::Open(const std::string& path) {
  std::error_code ec;
  std::filesystem::create_directories(path, ec);
  if (ec) return Status::Error(path + ": cannot create: " + ec.message());
  return std::unique_ptr<DiskFolder>(new DiskFolder(path));
}

std::string DiskFolder::Path(const std::string& name) const {
  return (std::filesystem::path(path_) / name).string();
}

Status DiskFolder::Write(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<std::pair<std::string, std::string>> paths;
  paths.reserve(files.size());
  for (const auto& [name, contents] : files) paths.emplace_back(Path(name), contents);
  return WriteFilesAtomically(paths);
}

}  // namespace ratslam
