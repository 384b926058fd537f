#pragma once
// The SQLite backend of the history (SPEC §10): one file, WAL (readers never wait for the
// writer), foreign keys on, a busy timeout for the other processes writing the same file,
// migrations in a transaction, statements with bound parameters only.
#include <memory>
#include <string>

#include "core/history/history.hpp"

namespace mixpilot::history {

struct SqliteSettings {
  // How long a write waits for another process's. Writes happen off the control thread (the
  // history writer, the CLI), so a long wait costs nothing, and a row given up is a flight lost.
  int busy_timeout_ms = 30000;
  bool create_folder = true;   // the file's missing folders are made (mode 700: a person's data)
};

// The store in the file `path` (created with the schema when missing). nullptr with the reason,
// naming the file: not a database, read-only, locked past the timeout, a newer schema.
std::unique_ptr<HistoryStore> open_sqlite(const std::string& path, std::string& error,
                                          const SqliteSettings& settings = {});

}  // namespace mixpilot::history
