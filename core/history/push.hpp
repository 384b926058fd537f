#pragma once
// `mixpilot history push`: a station's history copied into a training centre's shared database
// (SPEC §10), every table of the schema, idempotent. Flights with their metrics and, for a
// lesson step's attempt, the attempt's row (HistoryStore::copy_flight): a recorded flight is
// matched by its recording's hash, as everywhere in the history; a flight without a recording
// by its trainee, station and start time (to the millisecond), which no two flights share.
// Then each trainee's place in each lesson (HistoryStore::merge_progress): the newest row
// wins. Pushing again, or from an overlapping copy, adds nothing twice.
#include <cstddef>
#include <functional>
#include <string>

#include "core/history/history.hpp"

namespace mixpilot::history {

struct PushCounts {
  std::size_t flights = 0;        // in the source
  std::size_t added = 0;          // copied now
  std::size_t already_there = 0;  // the destination held them
  std::size_t attempts = 0;       // lesson attempts' rows copied now (with their flights or not)
  std::size_t progress = 0;       // lesson progress rows written now (the source's was newer)
};

// Copies every flight of `from` that `to` does not hold, oldest first, each in its own
// transaction, then the lessons' progress. `progress` (optional) after each flight: (done,
// total). false with the reason when a store cannot be read or a row cannot be written (the
// push stops there; the rows before it are in `to`, and pushing again goes on from there).
[[nodiscard]] bool push_history(HistoryStore& from, HistoryStore& to, PushCounts& counts,
                                std::string& error,
                                const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace mixpilot::history
