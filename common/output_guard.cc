#include "common/output_guard.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <system_error>
#include <utility>

#include "common/file_util.h"

namespace ratslam {
namespace {

namespace fs = std::filesystem;

// Files that only a ratslam run writes: a folder holding one holds an earlier run's outputs,
// even one written before the list existed.
constexpr const char* kRunMarkers[] = {"summary.json", "evaluation.json", "simulation.json",
                                       "call.json", "manifest.toml"};

// The guard's own entries at the top of the folder: never outputs, never scanned.
bool OwnEntry(const std::string& name) {
  return name == OutputGuard::kLockName || name == OutputGuard::kStagingName ||
         name == OutputGuard::kJournalName || name == OutputGuard::kIncompleteName;
}

// `path` relative to `folder` when it lies inside it (both made absolute and normal first).
std::optional<std::string> Inside(const fs::path& folder, const fs::path& path) {
  std::error_code ec;
  const fs::path f = fs::weakly_canonical(fs::absolute(folder, ec), ec);
  const fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) return std::nullopt;
  const fs::path r = p.lexically_relative(f);
  if (r.empty() || *r.begin() == ".." || r == ".") return std::nullopt;
  return r.generic_string();
}

// A line of the list or the journal is a plain relative path below the folder.
bool SafeEntry(const std::string& entry) {
  if (entry.empty() || entry.front() == '/') return false;
  for (const fs::path& part : fs::path(entry)) {
    if (part == ".." || part == ".") return false;
  }
  return !OwnEntry(fs::path(entry).begin()->string());
}

// The regular files below `folder` (relative paths), the guard's own entries left out.
std::set<std::string> Scan(const fs::path& folder) {
  std::set<std::string> files;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (it.depth() == 0 && OwnEntry(it->path().filename().string())) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_symlink(ec) || !it->is_regular_file(ec)) continue;
    files.insert(it->path().lexically_relative(folder).generic_string());
  }
  return files;
}

// Removes the folders above `file` up to (not including) `folder` that are now empty.
void PruneEmptyParents(const fs::path& folder, const fs::path& file) {
  std::error_code ec;
  for (fs::path dir = file.parent_path(); dir != folder && Inside(folder, dir);
       dir = dir.parent_path()) {
    if (!fs::is_empty(dir, ec) || ec || !fs::remove(dir, ec)) break;
  }
}

// Locks `folder`'s lock file without waiting; returns its descriptor. The file names the
// holder, so that a refused run can say who has the folder.
StatusOr<int> LockFolder(const fs::path& folder, const std::string& holder) {
  const fs::path path = folder / OutputGuard::kLockName;
  for (int attempt = 0; attempt < 3; ++attempt) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0) {
      return Status::Error(path.string() + ": cannot open the lock file: " + std::strerror(errno));
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      std::string who;
      char buffer[512];
      const ssize_t n = ::pread(fd, buffer, sizeof buffer - 1, 0);
      if (n > 0) who.assign(buffer, static_cast<size_t>(n));
      while (!who.empty() && (who.back() == '\n' || who.back() == '\0')) who.pop_back();
      ::close(fd);
      if (error != EWOULDBLOCK) {
        return Status::Error(path.string() + ": cannot lock: " + std::strerror(error));
      }
      return Status::Error(folder.string() + " is in use by another ratslam run" +
                           (who.empty() ? std::string() : " (" + who + ")") +
                           "; wait for it to finish or choose another output folder");
    }
    // The lock counts only if the file is still the one at the path (a finishing run removes
    // the lock file of a folder it created and left empty).
    struct stat held, current;
    if (::fstat(fd, &held) == 0 && ::lstat(path.c_str(), &current) == 0 &&
        held.st_ino == current.st_ino && held.st_dev == current.st_dev) {
      const std::string text = "pid " + std::to_string(::getpid()) +
                               (holder.empty() ? std::string() : ": " + holder) + "\n";
      if (::ftruncate(fd, 0) == 0) {
        (void)!::pwrite(fd, text.data(), text.size(), 0);
      }
      return fd;
    }
    ::close(fd);
  }
  return Status::Error(path.string() + ": the lock file keeps being replaced");
}

struct Journal {
  std::vector<std::string> moves;    // staged files, moved into the folder
  std::vector<std::string> removes;  // earlier-run files, removed
};

std::string JournalText(const Journal& journal) {
  std::ostringstream text;
  text << "# A ratslam run is moving its outputs from " << OutputGuard::kStagingName
       << "/ into this folder. If this file is\n"
          "# still here, the run was stopped: the next ratslam command on the folder completes "
          "the moves.\n";
  for (const std::string& m : journal.moves) text << "move " << m << "\n";
  for (const std::string& r : journal.removes) text << "remove " << r << "\n";
  return text.str();
}

StatusOr<Journal> ReadJournal(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return Status::Error(path.string() + ": cannot read");
  Journal journal;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line.front() == '#') continue;
    const size_t space = line.find(' ');
    const std::string verb = line.substr(0, space);
    const std::string entry = space == std::string::npos ? "" : line.substr(space + 1);
    if ((verb != "move" && verb != "remove") || !SafeEntry(entry)) {
      return Status::Error(path.string() + ":" + std::to_string(number) + ": '" + line +
                           "' is not 'move PATH' or 'remove PATH' with a path inside the folder; "
                           "remove the file and " +
                           OutputGuard::kStagingName +
                           "/ to give up the interrupted run's outputs");
    }
    (verb == "move" ? journal.moves : journal.removes).push_back(entry);
  }
  return journal;
}

// Carries out a journal; repeatable (a move whose staged file is gone was done already).
Status ApplyJournal(const fs::path& folder, const Journal& journal) {
  const fs::path staging = folder / OutputGuard::kStagingName;
  std::set<std::string> moved(journal.moves.begin(), journal.moves.end());
  for (const std::string& m : journal.moves) {
    const fs::path from = staging / m;
    const fs::path to = folder / m;
    std::error_code ec;
    if (!fs::is_regular_file(fs::symlink_status(from, ec))) continue;
    fs::create_directories(to.parent_path(), ec);
    if (std::rename(from.c_str(), to.c_str()) != 0) {
      return Status::Error(to.string() + ": cannot move the new output into place: " +
                           std::strerror(errno) + " (the next run on the folder tries again)");
    }
  }
  for (const std::string& r : journal.removes) {
    if (moved.count(r)) continue;
    const fs::path file = folder / r;
    std::error_code ec;
    if (fs::is_regular_file(fs::symlink_status(file, ec)) && fs::remove(file, ec)) {
      PruneEmptyParents(folder, file);
    }
  }
  std::error_code ec;
  fs::remove_all(staging, ec);
  if (ec) return Status::Error(staging.string() + ": cannot remove: " + ec.message());
  if (!fs::remove(folder / OutputGuard::kJournalName, ec) && ec) {
    return Status::Error((folder / OutputGuard::kJournalName).string() +
                         ": cannot remove: " + ec.message());
  }
  return Status::Ok();
}

// With the lock held: completes an interrupted commit, drops a killed run's staging folder.
Status Recover(const fs::path& folder) {
  const fs::path journal_path = folder / OutputGuard::kJournalName;
  std::error_code ec;
  if (fs::exists(fs::symlink_status(journal_path, ec))) {
    StatusOr<Journal> journal = ReadJournal(journal_path);
    if (!journal.ok()) return journal.status();
    return ApplyJournal(folder, *journal);
  }
  fs::remove_all(folder / OutputGuard::kStagingName, ec);
  if (ec) {
    return Status::Error((folder / OutputGuard::kStagingName).string() +
                         ": cannot remove a killed run's staging folder: " + ec.message());
  }
  return Status::Ok();
}

}  // namespace

StatusOr<FolderLock> FolderLock::Acquire(const std::string& folder, const std::string& holder) {
  StatusOr<int> fd = LockFolder(folder, holder);
  if (!fd.ok()) return fd.status();
  return FolderLock(*fd);
}

FolderLock& FolderLock::operator=(FolderLock&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

FolderLock::~FolderLock() {
  if (fd_ >= 0) ::close(fd_);
}

StatusOr<OutputGuard> OutputGuard::Begin(const std::string& folder, bool overwrite,
                                         const std::vector<std::string>& inputs,
                                         const std::string& holder) {
  if (folder.empty()) return Status::Error("the output folder is an empty path");
  OutputGuard guard;
  guard.folder_ = folder;
  guard.overwrite_ = overwrite;
  for (const std::string& input : inputs) {
    if (auto inside = Inside(folder, input)) guard.inputs_.insert(*inside);
  }
  std::error_code ec;
  const fs::file_status status = fs::status(folder, ec);
  if (fs::exists(status) && !fs::is_directory(status)) {
    return Status::Error(folder + ": the output folder is a file");
  }
  if (!fs::exists(status)) {
    fs::create_directories(folder, ec);
    if (ec) return Status::Error(folder + ": cannot create: " + ec.message());
    guard.created_folder_ = true;
  }
  StatusOr<int> lock = LockFolder(folder, holder);
  if (!lock.ok()) return lock.status();
  guard.lock_fd_ = *lock;
  RATSLAM_RETURN_IF_ERROR(Recover(folder));

  const std::set<std::string> before = Scan(folder);
  const fs::path list = fs::path(folder) / kListName;
  std::vector<std::string> evidence;
  if (before.count(kListName)) {
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
      if (before.count(line)) guard.earlier_.insert(line);
    }
    if (!guard.earlier_.empty()) evidence.push_back(kListName);
  }
  for (const char* marker : kRunMarkers) {
    if (before.count(marker)) evidence.push_back(marker);
  }
  if (!evidence.empty() && !overwrite) {
    std::string names;
    for (const std::string& e : evidence) names += (names.empty() ? "" : ", ") + e;
    return Status::Error(folder + " holds the outputs of an earlier run (" + names +
                         "); give --overwrite to replace them, or choose another output folder");
  }
  guard.staging_ = (fs::path(folder) / kStagingName).string();
  fs::create_directory(guard.staging_, ec);
  if (ec) return Status::Error(guard.staging_ + ": cannot create: " + ec.message());
  return guard;
}

OutputGuard::OutputGuard(OutputGuard&& other) noexcept { *this = std::move(other); }

OutputGuard& OutputGuard::operator=(OutputGuard&& other) noexcept {
  if (this == &other) return *this;
  if (lock_fd_ >= 0) ::close(lock_fd_);
  folder_ = std::move(other.folder_);
  staging_ = std::move(other.staging_);
  overwrite_ = other.overwrite_;
  created_folder_ = other.created_folder_;
  lock_fd_ = std::exchange(other.lock_fd_, -1);
  inputs_ = std::move(other.inputs_);
  earlier_ = std::move(other.earlier_);
  return *this;
}

OutputGuard::~OutputGuard() {
  if (lock_fd_ >= 0) ::close(lock_fd_);
}

std::string OutputGuard::Staged(const std::string& path) const {
  if (staging_.empty()) return path;
  if (auto inside = Inside(folder_, path)) return (fs::path(staging_) / *inside).string();
  return path;
}

bool OutputGuard::StagedSummary() const {
  std::error_code ec;
  for (const char* marker : kRunMarkers) {
    if (!staging_.empty() && fs::is_regular_file(fs::path(staging_) / marker, ec)) return true;
  }
  return false;
}

StatusOr<OutputGuard::Report> OutputGuard::Finish(Outcome outcome) {
  Report report;
  if (lock_fd_ < 0) return Status::Error(folder_ + ": the output guard was finished already");
  struct Release {
    int& fd;
    ~Release() {
      ::close(fd);
      fd = -1;
    }
  } release{lock_fd_};
  const fs::path folder(folder_);
  const fs::path staging(staging_);
  const std::set<std::string> staged = Scan(staging);
  std::error_code ec;

  if (outcome == Outcome::kFailed) {
    const fs::path incomplete = folder / kIncompleteName;
    if (staged.empty()) {
      fs::remove_all(staging, ec);
    } else {
      fs::remove_all(incomplete, ec);
      fs::rename(staging, incomplete, ec);
      if (ec)
        return Status::Error(incomplete.string() +
                             ": cannot keep the failed run's files: " + ec.message());
      report.incomplete = incomplete.string();
    }
  } else {
    Journal journal;
    journal.moves.assign(staged.begin(), staged.end());
    std::set<std::string> listed = staged;
    for (const std::string& path : earlier_) {
      if (staged.count(path) || inputs_.count(path)) continue;
      if (overwrite_) {
        journal.removes.push_back(path);
        report.removed.push_back(path);
      } else {
        listed.insert(path);
      }
    }
    std::ostringstream text;
    text << "# The files the last ratslam run wrote into this folder, one per line. `--overwrite`\n"
            "# replaces them and removes those the next run does not write again.\n";
    for (const std::string& path : listed) text << path << "\n";
    if (!listed.empty()) {
      RATSLAM_RETURN_IF_ERROR(WriteFileAtomically((staging / kListName).string(), text.str()));
      journal.moves.push_back(kListName);
    } else if (fs::exists(folder / kListName, ec)) {
      journal.removes.push_back(kListName);  // nothing of ours in the folder: no stale list
    }
    RATSLAM_RETURN_IF_ERROR(
        WriteFileAtomically((folder / kJournalName).string(), JournalText(journal)));
    RATSLAM_RETURN_IF_ERROR(ApplyJournal(folder, journal));
    fs::remove_all(folder / kIncompleteName, ec);
  }
  if (created_folder_ && staged.empty()) {
    // Nothing was written into a folder this run created: leave no trace of it.
    fs::remove(folder / kLockName, ec);
    fs::remove(folder, ec);
  }
  return report;
}

Status CheckReplaceable(const std::string& path, bool overwrite, const std::string& flag) {
  if (path.empty() || overwrite) return Status::Ok();
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(path, ec);
  if (!fs::exists(status)) return Status::Ok();
  return Status::Error(flag + " " + path + ": the file exists; give --overwrite to replace it, " +
                       "or choose another name");
}

Status RecoverOutputFolder(const std::string& folder) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(fs::path(folder) / OutputGuard::kJournalName, ec))) {
    return Status::Ok();
  }
  StatusOr<int> lock = LockFolder(folder, "completing an interrupted run's outputs");
  if (!lock.ok()) return lock.status();
  const Status recovered = Recover(folder);
  ::close(*lock);
  return recovered;
}

}  // namespace ratslam
