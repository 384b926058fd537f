#pragma once
// Inputs are regular files of bounded size: a FIFO would block a reader, /dev/zero never ends,
// and a huge file must not be read into memory. One check for every reader of the engine.
#include <sys/stat.h>

#include <cerrno>
#include <cstring>
#include <string>

namespace mixpilot {

// True when `path` is a regular file of at most max_bytes; otherwise false with
// "<path>: cannot open file (<system's reason>)", "<path>: expected a regular file, got ..." or
// "<path>: N bytes, more than the M ...".
inline bool check_input_file(const std::string& path, long long max_bytes, std::string& error) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    error = path + ": cannot open file (" + std::strerror(errno) + ")";
    return false;
  }
  if (!S_ISREG(st.st_mode)) {
    error = path + ": expected a regular file, got " +
            (S_ISDIR(st.st_mode) ? "a directory" : "a special file");
    return false;
  }
  if (st.st_size > max_bytes) {
    error = path + ": " + std::to_string(st.st_size) + " bytes, more than the " +
            std::to_string(max_bytes) + " such a file may have";
    return false;
  }
  return true;
}

}  // namespace mixpilot
