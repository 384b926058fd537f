#include "core/history/postgres_history.hpp"

namespace mixpilot::history {

// Until the PostgreSQL backend is built in, the factory says so (the URL is not repeated: it
// may hold a password).
std::unique_ptr<HistoryStore> open_postgres(const std::string& /*url*/, std::string& error) {
  error = "PostgreSQL support is not built into this mixpilot; use an SQLite file";
  return nullptr;
}

}  // namespace mixpilot::history
