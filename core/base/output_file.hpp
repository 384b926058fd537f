#pragma once
// Output files that never clobber anything by accident.
//
// An output is written to a temporary with a unique name beside its target,
// "<target>.XXXXXX.tmp", created with O_EXCL (so it is this process's own file), and moved into
// place only when complete: the target is either absent, its old contents, or the whole new
// file. Without permission to overwrite, the move refuses a target that appeared in the
// meantime (renameat2 with RENAME_NOREPLACE, or link() + unlink() where the file system lacks
// it), so two runs writing one path cannot corrupt each other: the second fails and keeps its
// temporary. Targets that are not regular files (devices, FIFOs, directories, symbolic links
// to one of these) are always refused, and so is a file this process has read as an input
// (core/base/input_file.hpp), by whatever name. A name too long for the suffix (at the file
// system's NAME_MAX) gives a temporary named after its first part.
//
// A failure never claims more than is true: a temporary is said to be kept only when it is
// still there (its folder may have been removed meanwhile), and one that nothing reached (a
// full disk) is removed rather than left empty.
//
// Messages name the path and give the system's reason, e.g.
//   out/run.mcap: cannot create a file in out: Permission denied
//   /dev/full: not a regular file (a character device)
#include <sys/types.h>

#include <cstdio>
#include <string>

namespace mixpilot {

// Checks, before any work is done, that `path` can become an output: it is absent, or a
// regular file (or a symbolic link to one) and `overwrite` is set; and its directory accepts
// new files (tried by creating and removing a temporary). False with the reason otherwise.
bool check_output_path(const std::string& path, bool overwrite, std::string& error);

// Whether an output may replace a file this process read as an input: only a file the program
// reads in order to rewrite it (the user's settings and gamepad mappings).
enum class InputReplacement { refused, allowed };

// True when `a` and `b` name the same output: the same normalized absolute path, or (when both
// exist) the same file through links.
bool same_output_path(const std::string& a, const std::string& b);

// True when `a` and `b` both exist and are one file (the same device and inode), whatever
// names, links or folders lead to them.
bool same_file(const std::string& a, const std::string& b);

// One output being written. Not thread-safe.
class OutputFile {
 public:
  OutputFile() = default;
  // Without commit() or discard(): the temporary is flushed, closed and left in place, so
  // nothing written is lost (a failed run can be inspected or recovered).
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // Checks `path` as check_output_path() does, then creates the temporary. A symbolic link to
  // a regular file is written through: its target is replaced.
  bool open(const std::string& path, bool overwrite, std::string& error,
            InputReplacement inputs = InputReplacement::refused);

  // The temporary's stream, fully buffered; nullptr when not open.
  std::FILE* stream() const { return file_; }
  bool is_open() const { return file_ != nullptr; }

  // Flushes, fsyncs and closes the temporary, then moves it to the target (without
  // `overwrite`: only if the target still does not exist). On failure the message says what
  // became of the output: kept in the temporary (complete, or what reached the disk, unless
  // `keep_partial` is false), or lost with its folder.
  bool commit(std::string& error, bool keep_partial = true);
  // Closes the temporary without moving it; it stays on disk. Idempotent.
  void abandon();
  // After a failed write: closes the temporary and keeps what reached the disk; returns what
  // became of it for the message ("; what was written is kept in X", or why nothing is).
  std::string keep_partial();
  // Closes and removes the temporary. Idempotent.
  void discard();

  const std::string& path() const { return path_; }            // the target, as given
  const std::string& temp_path() const { return temp_path_; }  // "" before open()

 private:
  std::FILE* file_ = nullptr;
  std::string path_;
  std::string target_;  // where the file goes: path_, or the file a symbolic link points to
  std::string temp_path_;
  bool overwrite_ = false;
  dev_t temp_dev_ = 0;  // the temporary's identity, to tell it from whatever is at its name later
  ino_t temp_ino_ = 0;

  // What became of a complete temporary that could not be moved into place.
  std::string complete_note() const;
  // What became of a temporary a write failed on; removed when empty or when !keep.
  std::string partial_note(bool keep);
};

// Moves `from` to `to` without replacing anything at `to` by link() + unlink(): the fallback
// of OutputFile::commit() on file systems without RENAME_NOREPLACE. Exposed for tests.
bool link_into_place(const std::string& from, const std::string& to, std::string& error);

}  // namespace mixpilot
