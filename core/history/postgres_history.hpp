#pragma once
// The PostgreSQL backend of the history (a training centre's shared database, SPEC §10): the
// schema and migrations of schema.hpp, run in one transaction under an advisory lock (stations
// opening a new database at once migrate it once); statements with bound parameters only; a
// flight added in one transaction, once per recording hash; a connect timeout (5 s unless the
// URL sets connect_timeout) so an unreachable server never holds a flight up for long.
// Credentials never leave this file: where() and every message name the server without the
// URL's user:password@ and without any password parameter.
#include <memory>
#include <string>

#include "core/history/history.hpp"

namespace mixpilot::history {

// `url`: postgresql://… or postgres://… (a libpq URL; a key=value connection string works
// too); nullptr with the reason, which never holds the password.
std::unique_ptr<HistoryStore> open_postgres(const std::string& url, std::string& error);

// `url` without its credentials: the user:password@ part, and every parameter whose name holds
// "password" (password=, sslpassword=), removed. For messages and where().
std::string redact_postgres_url(const std::string& url);

}  // namespace mixpilot::history
