#include "core/history/push.hpp"

namespace mixpilot::history {

bool push_history(HistoryStore& from, HistoryStore& to, PushCounts& counts, std::string& error,
                  const std::function<void(std::size_t, std::size_t)>& progress) {
  counts = {};
  std::vector<StoredFlight> flights;
  if (!from.query(Query{}, flights, error)) return false;
  counts.flights = flights.size();
  for (std::size_t i = 0; i < flights.size(); ++i) {
    const StoredFlight& f = flights[i];
    std::string why;
    const auto copied = to.copy_flight(f, why);
    if (!copied) {
      error = "flight " + std::to_string(i + 1) + " of " + std::to_string(flights.size()) + " (" +
              from.where() + " #" + std::to_string(f.id) + "): " + why;
      return false;
    }
    ++(copied->flight ? counts.added : counts.already_there);
    if (copied->attempt) ++counts.attempts;
    if (progress) progress(i + 1, flights.size());
  }
  // After the attempts: a trainee's place in a lesson follows from them where it was written.
  std::vector<LessonProgress> places;
  if (!from.lesson_progress("", places, error)) return false;
  for (const LessonProgress& p : places) {
    std::string why;
    const auto written = to.merge_progress(p, why);
    if (!written) {
      error = "the progress of " + p.trainee + " in " + p.lesson + " (" + from.where() + "): " + why;
      return false;
    }
    if (*written) ++counts.progress;
  }
  return true;
}

}  // namespace mixpilot::history
