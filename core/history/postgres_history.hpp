#pragma once
// The PostgreSQL backend of the history (a training centre's shared database, SPEC §10).
#include <memory>
#include <string>

#include "core/history/history.hpp"

namespace mixpilot::history {

// `url`: postgresql://… or postgres://…; nullptr with the reason, which never holds the
// password.
std::unique_ptr<HistoryStore> open_postgres(const std::string& url, std::string& error);

}  // namespace mixpilot::history
