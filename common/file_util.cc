#include "common/file_util.h"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <set>
#include <system_error>

namespace ratslam {

bool PathExists(const std::filesystem::path& path) noexcept {
  std::error_code ec;
  return std::filesystem::exists(path, ec);
}

bool IsDirectory(const std::filesystem::path& path) noexcept {
  std::error_code ec;
  return std::filesystem::is_directory(path, ec);
}

bool IsRegularFile(const std::filesystem::path& path) noexcept {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

namespace {

std::string TempPath(const std::string& path) { return path + ".tmp" + std::to_string(::getpid()); }

// Removes the `<name>.tmp<pid>` files that writers killed mid-save left in the folder of `path`.
// Each folder is scanned once per process: a data set's thousands of images go into one folder,
// and scanning it before every file made writing them quadratic.
void RemoveStaleTemps(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  {
    static std::mutex mutex;
    static std::set<std::string> scanned;
    std::error_code ec;
    const fs::path key = fs::weakly_canonical(folder, ec);
    const std::lock_guard<std::mutex> lock(mutex);
    if (!scanned.insert((ec ? folder : key).string()).second) return;
  }
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const size_t tmp = name.rfind(".tmp");
    if (tmp == std::string::npos || tmp == 0) continue;
    const std::string digits = name.substr(tmp + 4);
    if (digits.empty() || digits.size() > 9 ||
        digits.find_first_not_of("0123456789") != std::string::npos) {
      continue;
    }
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH) {
      std::error_code ignored;
      fs::remove(it->path(), ignored);
    }
  }
}

// Creates `temp` exclusively, never through a link: whatever is already at that name (a file of a
// process with a recycled pid, or a planted symbolic link to a file elsewhere) is removed, not
// written through.
int CreateExclusively(const std::string& temp) {
  constexpr int kFlags = O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC;
  int fd = ::open(temp.c_str(), kFlags, 0644);
  if (fd < 0 && errno == EEXIST && ::unlink(temp.c_str()) == 0) {
    fd = ::open(temp.c_str(), kFlags, 0644);
  }
  return fd;
}

// Writes (and, with `flush`, flushes to disk) `contents` to `temp`; on failure removes it and
// names `temp`.
Status WriteAndFlush(const std::string& temp, const std::string& contents, bool flush = true) {
  const int fd = CreateExclusively(temp);
  if (fd < 0) return Status::Error(temp + ": cannot create: " + std::strerror(errno));
  size_t written = 0;
  while (written < contents.size()) {
    const ssize_t n = ::write(fd, contents.data() + written, contents.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string reason = std::strerror(errno);
      ::close(fd);
      ::unlink(temp.c_str());
      return Status::Error(temp + ": write failed: " + reason);
    }
    written += static_cast<size_t>(n);
  }
  if (flush && ::fsync(fd) != 0) {
    const std::string reason = std::strerror(errno);
    ::close(fd);
    ::unlink(temp.c_str());
    return Status::Error(temp + ": cannot flush to disk: " + reason);
  }
  if (::close(fd) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(temp.c_str());
    return Status::Error(temp + ": cannot flush to disk: " + reason);
  }
  return Status::Ok();
}

}  // namespace

Status WriteFileAtomically(const std::string& path, const std::string& contents,
                           bool flush_to_disk) {
  if (flush_to_disk) return WriteFilesAtomically({{path, contents}});
  RemoveStaleTemps(path);
  const std::string temp = TempPath(path);
  RATSLAM_RETURN_IF_ERROR(WriteAndFlush(temp, contents, /*flush=*/false));
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(temp.c_str());
    return Status::Error(path + ": cannot rename the temporary file into place: " + reason);
  }
  return Status::Ok();
}

Status WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<std::string> temps;
  for (const auto& [path, contents] : files) {
    RemoveStaleTemps(path);
    const std::string temp = TempPath(path);
    const Status written = WriteAndFlush(temp, contents);
    if (!written.ok()) {
      for (const std::string& t : temps) ::unlink(t.c_str());
      return written;
    }
    temps.push_back(temp);
  }
  for (size_t i = 0; i < files.size(); ++i) {
    if (std::rename(temps[i].c_str(), files[i].first.c_str()) != 0) {
      const std::string reason = std::strerror(errno);
      for (size_t k = i; k < temps.size(); ++k) ::unlink(temps[k].c_str());
      return Status::Error(files[i].first +
                           ": cannot rename the temporary file into place: " + reason);
    }
  }
  return Status::Ok();
}

}  // namespace ratslam
