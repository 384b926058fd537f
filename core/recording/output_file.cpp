#include "core/recording/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <system_error>

namespace mixpilot {

namespace {

namespace fs = std::filesystem;

std::string reason(int err) { return std::strerror(err); }

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

// What is at `path` decides where an output goes. Sets `target` to the file to replace or
// create (a symbolic link to a regular file is followed); false with the reason when the path
// must not be written.
bool resolve_target(const std::string& path, bool overwrite, std::string& target,
                    std::string& error) {
  if (path.empty()) {
    error = "empty output path";
    return false;
  }
  const fs::path name = fs::path(path).filename();
  if (name.empty() || name == "." || name == "..") {
    error = path + ": names a directory, not a file";
    return false;
  }
  target = path;
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return true;  // a new file
    error = path + ": cannot check the output path: " + reason(errno);
    return false;
  }
  if (S_ISLNK(st.st_mode)) {
    struct stat to {};
    if (::stat(path.c_str(), &to) != 0) {
      error = path + ": symbolic link to nothing usable: " + reason(errno);
      return false;
    }
    if (!S_ISREG(to.st_mode)) {
      error = path + ": not a regular file (a symbolic link to " + kind_of(to.st_mode) + ")";
      return false;
    }
    std::error_code ec;
    const fs::path real = fs::canonical(path, ec);
    if (ec) {
      error = path + ": cannot resolve the symbolic link: " + ec.message();
      return false;
    }
    target = real.string();
  } else if (!S_ISREG(st.st_mode)) {
    error = path + ": not a regular file (" + kind_of(st.st_mode) + ")";
    return false;
  }
  if (!overwrite) {
    error = path + ": " + reason(EEXIST) + " (refusing to overwrite it)";
    return false;
  }
  return true;
}

std::string directory_of(const std::string& target) {
  const fs::path dir = fs::path(target).parent_path();
  return dir.empty() ? std::string(".") : dir.string();
}

// Creates "<target>.XXXXXX.tmp" with O_EXCL (mode 0666 less the umask, like any new file).
// Returns the descriptor, or -1 with errno set.
int create_unique(const std::string& target, std::string& temp_path) {
  static constexpr char kChars[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
  thread_local std::mt19937_64 rng(std::random_device{}() ^
                                   (std::uint64_t(::getpid()) << 32));
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string suffix(6, 'x');
    for (char& c : suffix) c = kChars[rng() % (sizeof kChars - 1)];
    temp_path = target + "." + suffix + ".tmp";
    const int fd = ::open(temp_path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST) return fd;
  }
  errno = EEXIST;
  return -1;
}

// Makes a completed rename durable (best effort: some file systems refuse fsync on a
// directory, and the file itself is already synced).
void sync_directory(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  (void)::fsync(fd);
  ::close(fd);
}

}  // namespace

bool check_output_path(const std::string& path, bool overwrite, std::string& error) {
  std::string target;
  if (!resolve_target(path, overwrite, target, error)) return false;
  std::string probe;
  const int fd = create_unique(target, probe);
  if (fd < 0) {
    error = path + ": cannot create a file in " + directory_of(target) + ": " + reason(errno);
    return false;
  }
  ::close(fd);
  ::unlink(probe.c_str());
  return true;
}

bool same_output_path(const std::string& a, const std::string& b) {
  std::error_code ea, eb;
  const fs::path pa = fs::weakly_canonical(fs::absolute(a, ea), ea);
  const fs::path pb = fs::weakly_canonical(fs::absolute(b, eb), eb);
  if (!ea && !eb && pa == pb) return true;
  if (fs::path(a).lexically_normal() == fs::path(b).lexically_normal()) return true;
  struct stat sa {}, sb {};
  return ::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev &&
         sa.st_ino == sb.st_ino;
}

bool link_into_place(const std::string& from, const std::string& to, std::string& error) {
  if (::link(from.c_str(), to.c_str()) != 0) {
    const int err = errno;
    error = to + ": " + reason(err) +
            (err == EEXIST ? " (it appeared while this run was writing; not replaced)" : "") +
            "; the output is kept in " + from;
    return false;
  }
  ::unlink(from.c_str());  // both names refer to the finished file; the temporary one goes
  return true;
}

OutputFile::~OutputFile() { abandon(); }

bool OutputFile::open(const std::string& path, bool overwrite, std::string& error) {
  if (file_ != nullptr) {
    error = path + ": output already open on " + path_;
    return false;
  }
  path_ = path;
  overwrite_ = overwrite;
  temp_path_.clear();
  if (!resolve_target(path, overwrite, target_, error)) return false;
  std::string temp;
  const int fd = create_unique(target_, temp);
  if (fd < 0) {
    error = path + ": cannot create a file in " + directory_of(target_) + ": " + reason(errno);
    return false;
  }
  file_ = ::fdopen(fd, "wb");
  if (file_ == nullptr) {
    error = temp + ": cannot open a stream: " + reason(errno);
    ::close(fd);
    ::unlink(temp.c_str());
    return false;
  }
  temp_path_ = std::move(temp);
  std::setvbuf(file_, nullptr, _IOFBF, 1 << 16);
  return true;
}

bool OutputFile::commit(std::string& error) {
  if (file_ == nullptr) {
    error = path_.empty() ? std::string("output not open") : path_ + ": output not open";
    return false;
  }
  const std::string kept = "; the output is kept in " + temp_path_;
  // Durable before visible: the data reaches the disk before the name points at it.
  if (std::fflush(file_) != 0 || ::fsync(::fileno(file_)) != 0) {
    error = temp_path_ + ": write failed: " + reason(errno) + kept;
    abandon();
    return false;
  }
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (rc != 0) {
    error = temp_path_ + ": close failed: " + reason(errno) + kept;
    return false;
  }
  if (overwrite_) {
    // What is at the target now must still be a regular file (or nothing): a device or a
    // directory that appeared meanwhile is not replaced.
    struct stat st {};
    if (::lstat(target_.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
      error = path_ + ": not a regular file (" + kind_of(st.st_mode) + "); not replaced" + kept;
      return false;
    }
    if (std::rename(temp_path_.c_str(), target_.c_str()) != 0) {
      error = path_ + ": cannot move the output into place: " + reason(errno) + kept;
      return false;
    }
  } else if (::renameat2(AT_FDCWD, temp_path_.c_str(), AT_FDCWD, target_.c_str(),
                         RENAME_NOREPLACE) != 0) {
    const int err = errno;
    if (err != EINVAL && err != ENOSYS && err != EOPNOTSUPP) {
      error = path_ + ": " + reason(err) +
              (err == EEXIST ? " (it appeared while this run was writing; not replaced)" : "") +
              kept;
      return false;
    }
    if (!link_into_place(temp_path_, target_, error)) return false;
  }
  sync_directory(directory_of(target_));
  temp_path_.clear();
  return true;
}

void OutputFile::abandon() {
  if (file_ == nullptr) return;
  std::fflush(file_);
  std::fclose(file_);
  file_ = nullptr;
}

void OutputFile::discard() {
  abandon();
  if (!temp_path_.empty()) ::unlink(temp_path_.c_str());
  temp_path_.clear();
}

}  // namespace mixpilot
