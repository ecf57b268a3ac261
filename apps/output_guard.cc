#include "apps/output_guard.h"

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <system_error>

#include "common/file_util.h"

namespace ratslam {
namespace {

namespace fs = std::filesystem;

// Files that only a ratslam run writes: a folder holding one holds an earlier run's outputs,
// even one written before the list existed.
constexpr const char* kRunMarkers[] = {"summary.json", "evaluation.json", "simulation.json",
                                       "call.json", "manifest.toml"};

// `path` relative to `folder` when it lies inside it (both made absolute and normal first).
std::optional<std::string> Inside(const fs::path& folder, const fs::path& path) {
  std::error_code ec;
  const fs::path f = fs::weakly_canonical(fs::absolute(folder, ec), ec);
  const fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) return std::nullopt;
  const fs::path r = p.lexically_relative(f);
  if (r.empty() || *r.begin() == "..") return std::nullopt;
  return r.generic_string();
}

// A line of the list is a plain relative path below the folder.
bool SafeEntry(const std::string& entry) {
  if (entry.empty() || entry.front() == '/') return false;
  for (const fs::path& part : fs::path(entry)) {
    if (part == ".." || part == ".") return false;
  }
  return true;
}

}  // namespace

OutputGuard::Snapshot OutputGuard::Scan(const std::string& folder) {
  Snapshot snapshot;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    struct stat st;
    if (::stat(it->path().c_str(), &st) != 0) continue;
    FileStamp stamp;
    stamp.inode = static_cast<uint64_t>(st.st_ino);
    stamp.mtime_ns = static_cast<int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec;
    stamp.size = static_cast<uint64_t>(st.st_size);
    snapshot[it->path().lexically_relative(folder).generic_string()] = stamp;
  }
  return snapshot;
}

StatusOr<OutputGuard> OutputGuard::Begin(const std::string& folder, bool overwrite,
                                         const std::vector<std::string>& inputs) {
  OutputGuard guard;
  guard.folder_ = folder;
  guard.overwrite_ = overwrite;
  for (const std::string& input : inputs) {
    if (auto inside = Inside(folder, input)) guard.inputs_.insert(*inside);
  }
  std::error_code ec;
  if (!fs::exists(folder, ec)) return guard;
  if (!fs::is_directory(folder, ec)) {
    return Status::Error(folder + ": the output folder is a file");
  }
  guard.before_ = Scan(folder);
  const fs::path list = fs::path(folder) / kListName;
  std::vector<std::string> evidence;
  if (guard.before_.count(kListName)) {
    std::ifstream in(list);
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      if (line.empty() || line.front() == '#') continue;
      if (!SafeEntry(line)) {
        return Status::Error(list.string() + ":" + std::to_string(number) + ": '" + line +
                             "' is not a path inside the folder; remove the file or the line");
      }
      if (guard.before_.count(line)) guard.earlier_.insert(line);
    }
    if (!guard.earlier_.empty()) evidence.push_back(kListName);
  }
  for (const char* marker : kRunMarkers) {
    if (guard.before_.count(marker)) evidence.push_back(marker);
  }
  if (!evidence.empty() && !overwrite) {
    std::string names;
    for (const std::string& e : evidence) names += (names.empty() ? "" : ", ") + e;
    return Status::Error(folder + " holds the outputs of an earlier run (" + names +
                         "); give --overwrite to replace them, or choose another output folder");
  }
  return guard;
}

StatusOr<std::vector<std::string>> OutputGuard::Finish(bool succeeded) {
  std::error_code exists_ec;
  if (!fs::is_directory(folder_, exists_ec)) return std::vector<std::string>();  // nothing written
  const Snapshot after = Scan(folder_);
  std::set<std::string> written;
  for (const auto& [path, stamp] : after) {
    if (path == kListName) continue;
    auto it = before_.find(path);
    if (it == before_.end() || !(it->second == stamp)) written.insert(path);
  }
  std::vector<std::string> removed;
  std::set<std::string> listed = written;
  for (const std::string& path : earlier_) {
    if (written.count(path) || inputs_.count(path) || !after.count(path)) continue;
    if (!(overwrite_ && succeeded)) {
      listed.insert(path);  // still there: a later --overwrite removes it
      continue;
    }
    std::error_code ec;
    const fs::path full = fs::path(folder_) / path;
    if (!fs::remove(full, ec) || ec) {
      listed.insert(path);
      continue;
    }
    removed.push_back(path);
    // Directories emptied by the removal go too (animation/ of an earlier run).
    for (fs::path dir = full.parent_path();
         dir != fs::path(folder_) && Inside(folder_, dir) && fs::is_empty(dir, ec) && !ec;
         dir = dir.parent_path()) {
      if (!fs::remove(dir, ec)) break;
    }
  }
  const std::string list = (fs::path(folder_) / kListName).string();
  if (listed.empty()) {  // nothing of ours in the folder: no list (and no stale one)
    std::error_code ec;
    fs::remove(list, ec);
    return removed;
  }
  std::ostringstream text;
  text << "# The files the last ratslam run wrote into this folder, one per line. `--overwrite`\n"
          "# replaces them and removes those the next run does not write again.\n";
  for (const std::string& path : listed) text << path << "\n";
  Status status = WriteFileAtomically(list, text.str());
  if (!status.ok()) return status;
  return removed;
}

}  // namespace ratslam
