#include "core/history/push.hpp"

#include <set>
#include <tuple>

namespace mixpilot::history {

namespace {

// An unrecorded flight's identity: who flew, where, when.
using Key = std::tuple<std::string, std::string, std::int64_t>;
Key key_of(const FlightRecord& f) { return {f.trainee, f.station, f.started_unix_ms}; }

}  // namespace

bool push_history(HistoryStore& from, HistoryStore& to, PushCounts& counts, std::string& error,
                  const std::function<void(std::size_t, std::size_t)>& progress) {
  counts = {};
  std::vector<StoredFlight> flights;
  if (!from.query(Query{}, flights, error)) return false;
  counts.flights = flights.size();
  // The destination's unrecorded flights of the trainees that have some here.
  std::set<Key> there;
  std::set<std::string> asked;
  for (const StoredFlight& f : flights) {
    if (!f.recording_hash.empty() || !asked.insert(f.trainee).second) continue;
    Query q;
    q.trainee = f.trainee;
    std::vector<StoredFlight> theirs;
    if (!to.query(q, theirs, error)) return false;
    for (const StoredFlight& t : theirs)
      if (t.recording_hash.empty()) there.insert(key_of(t));
  }
  for (std::size_t i = 0; i < flights.size(); ++i) {
    const StoredFlight& f = flights[i];
    const bool unrecorded = f.recording_hash.empty();
    if (unrecorded && there.count(key_of(f)) != 0) {
      ++counts.already_there;
    } else {
      std::string why;
      const auto added = to.add(f, why);
      if (!added) {
        error = "flight " + std::to_string(i + 1) + " of " + std::to_string(flights.size()) + " (" +
                from.where() + " #" + std::to_string(f.id) + "): " + why;
        return false;
      }
      if (*added == HistoryStore::Added::added) {
        ++counts.added;
        if (unrecorded) there.insert(key_of(f));
      } else {
        ++counts.already_there;
      }
    }
    if (progress) progress(i + 1, flights.size());
  }
  return true;
}

}  // namespace mixpilot::history
