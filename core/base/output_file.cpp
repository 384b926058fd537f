#include "core/base/output_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <system_error>

#include "core/base/input_file.hpp"

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
                    std::string& error, InputReplacement inputs = InputReplacement::refused) {
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
  struct stat file {};
  if (inputs == InputReplacement::refused && ::stat(path.c_str(), &file) == 0) {
    if (const auto read_as = input_read_as(file)) {
      error = path + ": this run read it as an input (" + *read_as +
              "); an output never replaces an input";
      return false;
    }
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

// The longest file name the folder `dir` takes (NAME_MAX of its file system).
std::size_t name_max(const std::string& dir) {
  const long n = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  return n > 0 ? std::size_t(n) : 255;
}

// `name` cut to at most `bytes` bytes, not inside a UTF-8 sequence.
std::string cut_name(const std::string& name, std::size_t bytes) {
  if (name.size() <= bytes) return name;
  std::size_t n = bytes;
  while (n > 0 && (static_cast<unsigned char>(name[n]) & 0xC0) == 0x80) --n;
  return name.substr(0, n);
}

// Creates "<target>.XXXXXX.tmp" with O_EXCL (mode 0666 less the umask, like any new file). A
// target whose name leaves no room for the suffix gives a temporary named after its first part.
// Returns the descriptor, or -1 with errno set.
int create_unique(const std::string& target, std::string& temp_path) {
  static constexpr char kChars[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
  static constexpr std::size_t kSuffix = 11;  // ".XXXXXX.tmp"
  thread_local std::mt19937_64 rng(std::random_device{}() ^
                                   (std::uint64_t(::getpid()) << 32));
  const fs::path t(target);
  const std::string dir = t.parent_path().empty() ? std::string(".") : t.parent_path().string();
  const std::size_t room = name_max(dir);
  const std::string name = t.filename().string();
  const std::string base =
      name.size() + kSuffix <= room
          ? target
          : (t.parent_path() / cut_name(name, room > kSuffix ? room - kSuffix : 1)).string();
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string suffix(6, 'x');
    for (char& c : suffix) c = kChars[rng() % (sizeof kChars - 1)];
    temp_path = base + "." + suffix + ".tmp";
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

bool same_file(const std::string& a, const std::string& b) {
  struct stat sa {}, sb {};
  return !a.empty() && !b.empty() && ::stat(a.c_str(), &sa) == 0 &&
         ::stat(b.c_str(), &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

bool link_into_place(const std::string& from, const std::string& to, std::string& error) {
  if (::link(from.c_str(), to.c_str()) != 0) {
    const int err = errno;
    struct stat st {};
    error = to + ": " + reason(err) +
            (err == EEXIST ? " (it appeared while this run was writing; not replaced)" : "") +
            (::stat(from.c_str(), &st) == 0
                 ? "; the output is kept in " + from
                 : "; the output is lost: " + from + " is gone (its folder was removed or moved)");
    return false;
  }
  ::unlink(from.c_str());  // both names refer to the finished file; the temporary one goes
  return true;
}

OutputFile::~OutputFile() { abandon(); }

bool OutputFile::open(const std::string& path, bool overwrite, std::string& error,
                      InputReplacement inputs) {
  if (file_ != nullptr) {
    error = path + ": output already open on " + path_;
    return false;
  }
  path_ = path;
  overwrite_ = overwrite;
  temp_path_.clear();
  if (!resolve_target(path, overwrite, target_, error, inputs)) return false;
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
  struct stat st {};
  if (::fstat(fd, &st) == 0) {
    temp_dev_ = st.st_dev;
    temp_ino_ = st.st_ino;
  }
  std::setvbuf(file_, nullptr, _IOFBF, 1 << 16);
  return true;
}

std::string OutputFile::complete_note() const {
  struct stat st {};
  if (::lstat(temp_path_.c_str(), &st) == 0 && st.st_dev == temp_dev_ && st.st_ino == temp_ino_)
    return "; the output is kept in " + temp_path_;
  return "; the output is lost: its temporary " + temp_path_ +
         " is gone (its folder was removed or moved while it was written)";
}

std::string OutputFile::partial_note(bool keep) {
  struct stat st {};
  if (::lstat(temp_path_.c_str(), &st) != 0 || st.st_dev != temp_dev_ || st.st_ino != temp_ino_) {
    const std::string gone = temp_path_;
    temp_path_.clear();
    return "; nothing is kept: " + gone +
           " is gone (its folder was removed or moved while it was written)";
  }
  if (st.st_size == 0 || !keep) {
    ::unlink(temp_path_.c_str());
    temp_path_.clear();
    return st.st_size == 0 ? "; nothing had reached the disk, so no file is kept"
                           : "; the incomplete file was removed";
  }
  return "; what was written is kept in " + temp_path_;
}

std::string OutputFile::keep_partial() {
  abandon();
  return temp_path_.empty() ? std::string() : partial_note(true);
}

bool OutputFile::commit(std::string& error, bool keep_partial) {
  if (file_ == nullptr) {
    error = path_.empty() ? std::string("output not open") : path_ + ": output not open";
    return false;
  }
  // Durable before visible: the data reaches the disk before the name points at it. A write
  // that failed earlier (the caller may not have checked) fails the whole output.
  const bool failed_before = std::ferror(file_) != 0;
  if (failed_before || std::fflush(file_) != 0 || ::fsync(::fileno(file_)) != 0) {
    const std::string why = failed_before ? std::string("an earlier write failed") : reason(errno);
    abandon();
    const std::string note = partial_note(keep_partial);
    error = path_ + ": write failed: " + why + note;
    return false;
  }
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (rc != 0) {
    const int err = errno;
    const std::string note = partial_note(keep_partial);
    error = path_ + ": close failed: " + reason(err) + note;
    return false;
  }
  if (overwrite_) {
    // What is at the target now must still be a regular file (or nothing): a device or a
    // directory that appeared meanwhile is not replaced.
    struct stat st {};
    if (::lstat(target_.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
      error = path_ + ": not a regular file (" + kind_of(st.st_mode) + "); not replaced" +
              complete_note();
      return false;
    }
    if (std::rename(temp_path_.c_str(), target_.c_str()) != 0) {
      const std::string why = reason(errno);
      error = path_ + ": cannot move the output into place: " + why + complete_note();
      return false;
    }
  } else if (::renameat2(AT_FDCWD, temp_path_.c_str(), AT_FDCWD, target_.c_str(),
                         RENAME_NOREPLACE) != 0) {
    const int err = errno;
    if (err != EINVAL && err != ENOSYS && err != EOPNOTSUPP) {
      error = path_ + ": " + reason(err) +
              (err == EEXIST ? " (it appeared while this run was writing; not replaced)" : "") +
              complete_note();
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
