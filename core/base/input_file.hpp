#pragma once
// Reading what a user hands the program, one way for every reader: inputs are regular files of
// bounded size (a FIFO would block a reader, /dev/zero never ends, a huge file must not be read
// into memory), text comes in whatever line ends and byte-order mark an editor wrote, and any of
// it echoed in a message is made printable first (a terminal must never receive its escape
// sequences from a file).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mixpilot {

namespace input_file_detail {

inline std::string kind_of(mode_t m) {
  if (S_ISDIR(m)) return "a directory";
  if (S_ISFIFO(m)) return "a named pipe";
  if (S_ISSOCK(m)) return "a socket";
  if (S_ISCHR(m) || S_ISBLK(m)) return "a device";
  return "a special file";
}

inline std::string too_big(const std::string& path, long long size, long long max_bytes) {
  return path + ": " + std::to_string(size) + " bytes, more than the " +
         std::to_string(max_bytes) + " such a file may have";
}

// Why stat() failed on `path`, said plainly: a symbolic link whose target is missing reads as
// such, not as "no such file" of the link the user can see.
inline std::string open_error(const std::string& path, int err) {
  struct stat l {};
  if (err == ENOENT && ::lstat(path.c_str(), &l) == 0 && S_ISLNK(l.st_mode))
    return path + ": cannot open file (a symbolic link to a missing file)";
  return path + ": cannot open file (" + std::strerror(err) + ")";
}

// A file as it was read: its change time tells it from a later file that reuses the inode
// number, and from the same file rewritten since.
struct ReadFile {
  dev_t dev;
  ino_t ino;
  struct timespec ctime;
  std::string path;

  bool is(const struct stat& st) const {
    return dev == st.st_dev && ino == st.st_ino && ctime.tv_sec == st.st_ctim.tv_sec &&
           ctime.tv_nsec == st.st_ctim.tv_nsec;
  }
};

// The files this process has read as inputs (read_input_file(), recordings): an output never
// replaces one of them (core/base/output_file.hpp), whatever name it is given by.
inline std::vector<ReadFile>& files_read(std::unique_lock<std::mutex>& lock) {
  static std::mutex mutex;
  static std::vector<ReadFile> files;
  lock = std::unique_lock<std::mutex>(mutex);
  return files;
}

}  // namespace input_file_detail

// Notes that the file `st` describes was read as `path` (see input_read_as()).
inline void note_input_read(const struct stat& st, const std::string& path) {
  std::unique_lock<std::mutex> lock;
  auto& files = input_file_detail::files_read(lock);
  for (const auto& f : files)
    if (f.is(st)) return;
  files.push_back({st.st_dev, st.st_ino, st.st_ctim, path});
}

// The name under which this process read the file `st` describes as an input, if it did and
// the file has not changed since.
inline std::optional<std::string> input_read_as(const struct stat& st) {
  std::unique_lock<std::mutex> lock;
  for (const auto& f : input_file_detail::files_read(lock))
    if (f.is(st)) return f.path;
  return std::nullopt;
}

// True when `path` names a regular file of at most max_bytes; otherwise false with
// "<path>: cannot open file (<system's reason>)", "<path>: expected a regular file, got a
// directory" or "<path>: N bytes, more than the M such a file may have". An empty path is
// refused as such (it would otherwise read as the current folder or "no such file").
inline bool check_input_file(const std::string& path, long long max_bytes, std::string& error) {
  if (path.empty()) {
    error = "an empty file name was given where a file is expected";
    return false;
  }
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    error = input_file_detail::open_error(path, errno);
    return false;
  }
  if (!S_ISREG(st.st_mode)) {
    error = path + ": expected a regular file, got " + input_file_detail::kind_of(st.st_mode);
    return false;
  }
  if (st.st_size > max_bytes) {
    error = input_file_detail::too_big(path, st.st_size, max_bytes);
    return false;
  }
  return true;
}

// The whole content of a regular file of at most max_bytes, with check_input_file()'s errors.
// The file is opened without blocking and checked on the open descriptor, so a FIFO put in
// place between a check and the read cannot hang the reader.
inline bool read_input_file(const std::string& path, long long max_bytes, std::string& text,
                            std::string& error) {
  if (!check_input_file(path, max_bytes, error)) return false;
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    error = input_file_detail::open_error(path, errno);
    return false;
  }
  struct stat st {};
  bool ok = ::fstat(fd, &st) == 0;
  if (!ok) {
    error = path + ": cannot open file (" + std::strerror(errno) + ")";
  } else if (!S_ISREG(st.st_mode)) {
    ok = false;
    error = path + ": expected a regular file, got " + input_file_detail::kind_of(st.st_mode);
  }
  std::string out;
  char buf[1 << 16];
  while (ok) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      ok = false;
      error = path + ": read error (" + std::strerror(errno) + ")";
    } else if (static_cast<long long>(out.size()) + n > max_bytes) {  // it grew while read
      ok = false;
      error = input_file_detail::too_big(path, static_cast<long long>(out.size()) + n, max_bytes);
    } else {
      out.append(buf, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  if (ok) {
    note_input_read(st, path);
    text = std::move(out);
  }
  return ok;
}

// Text as a reader of lines wants it: a leading UTF-8 byte-order mark dropped, CR LF and lone
// CR line ends (old Mac editors, some spreadsheet exports) made LF.
inline std::string normalize_text(std::string_view text) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\r') {
      out += '\n';
      if (i + 1 < text.size() && text[i + 1] == '\n') ++i;
    } else {
      out += text[i];
    }
  }
  return out;
}

namespace input_file_detail {

// `text` with control characters and bytes that are not UTF-8 as \xNN; with `quoted`, a quote
// and a backslash escaped too (the text is shown inside quotes); cut at max_chars with "…".
inline std::string escaped(std::string_view text, std::size_t max_chars, bool quoted) {
  std::string out;
  std::size_t chars = 0;
  const auto hex = [&](unsigned char c) {
    char b[8];
    std::snprintf(b, sizeof b, "\\x%02X", c);
    out += b;
  };
  for (std::size_t i = 0; i < text.size();) {
    if (chars == max_chars) {
      out += "…";
      break;
    }
    const auto c = static_cast<unsigned char>(text[i]);
    std::size_t len = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    bool valid = len > 0 && i + len <= text.size();
    for (std::size_t k = 1; valid && k < len; ++k)
      valid = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
    if (valid && len == 2) valid = c >= 0xC2;  // no overlong forms
    if (!valid) {
      hex(c);
      ++i;
    } else if (len == 1 && (c < 0x20 || c == 0x7F)) {
      hex(c);
      ++i;
    } else if (len == 1 && quoted && (c == '"' || c == '\\')) {
      out += '\\';
      out += char(c);
      ++i;
    } else if (len == 2 && c == 0xC2 && static_cast<unsigned char>(text[i + 1]) < 0xA0) {
      hex(c);  // C1 controls (U+0080..U+009F), e.g. the 8-bit CSI
      hex(static_cast<unsigned char>(text[i + 1]));
      i += 2;
    } else {
      out.append(text.substr(i, len));
      i += len;
    }
    ++chars;
  }
  return out;
}

}  // namespace input_file_detail

// `text` safe to print inside quotes: control characters and bytes that are not UTF-8 appear
// as \xNN (escape sequences never reach the terminal), a quote as \", and anything beyond
// max_chars is cut with "…".
inline std::string printable(std::string_view text, std::size_t max_chars = 60) {
  return input_file_detail::escaped(text, max_chars, true);
}

// A whole message safe for a terminal: control characters and bytes that are not UTF-8 as
// \xNN, the rest (quotes included) as it is; line breaks stay when `multiline` (the lines of a
// multi-line message). For messages that carry text from a file or a recording.
inline std::string escape_controls(std::string_view text, bool multiline = false) {
  std::string out;
  out.reserve(text.size());
  while (true) {
    const std::size_t nl = multiline ? text.find('\n') : std::string_view::npos;
    out += input_file_detail::escaped(text.substr(0, nl), std::string_view::npos, false);
    if (nl == std::string_view::npos) break;
    out += '\n';
    text.remove_prefix(nl + 1);
  }
  return out;
}

// The last `lines` lines of the text file `path` (a log a child process wrote), each on a line
// of its own after `prefix`, made printable; "" when it cannot be read.
inline std::string last_lines(const std::string& path, std::size_t lines, std::string_view prefix) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return "";
  std::vector<std::string> last;  // a ring of `lines` lines
  std::size_t count = 0;
  std::string line;
  for (int c; lines > 0 && (c = std::getc(f)) != EOF;) {
    if (c != '\n') {
      line += char(c);
      continue;
    }
    if (last.size() < lines) last.push_back(std::move(line));
    else last[count % lines] = std::move(line);
    ++count;
    line.clear();
  }
  std::fclose(f);
  if (!line.empty()) {
    if (last.size() < lines) last.push_back(std::move(line));
    else if (lines > 0) last[count % lines] = std::move(line);
    ++count;
  }
  std::string out;
  const std::size_t first = count > lines ? count % lines : 0;
  for (std::size_t k = 0; k < last.size(); ++k)
    out.append("\n").append(prefix).append(
        input_file_detail::escaped(last[(first + k) % last.size()], 400, false));
  return out;
}

}  // namespace mixpilot
