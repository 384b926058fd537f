#include "app/history_writer.hpp"

#include <filesystem>

#include "app/progress.hpp"
#include "core/base/content_hash.hpp"

namespace mixpilot::cli {

// How many of the newest flights the Progress panel shows.
constexpr std::int64_t kProgressFlights = 200;

HistoryWriter::HistoryWriter(const std::string& location)
    : HistoryWriter(Opener([location](std::string& error) {
        return history::open_history(location, error);
      })) {
  const std::lock_guard<std::mutex> lock(mutex_);  // the thread runs already
  if (location.empty()) file_ = history::default_history_path();
  else if (location.starts_with("sqlite:")) file_ = location.substr(7);
  else if (!location.starts_with("postgres")) file_ = location;
}

HistoryWriter::HistoryWriter(Opener open) : open_(std::move(open)) {
  thread_ = std::thread([this] { run(); });
}

HistoryWriter::~HistoryWriter() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void HistoryWriter::remember(history::FlightRecord record, std::string hash_path,
                             std::optional<history::LessonAttempt> attempt) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    Job j;
    j.record = std::move(record);
    j.hash_path = std::move(hash_path);
    j.attempt = std::move(attempt);
    jobs_.push_back(std::move(j));
  }
  wake_.notify_all();
}

void HistoryWriter::show(std::string trainee, std::string scenario) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    trainee_ = std::move(trainee);
    scenario_ = std::move(scenario);
    // One load is enough however often it is asked for before it runs.
    for (const Job& j : jobs_)
      if (j.kind == Job::Kind::load) return;
    Job j;
    j.kind = Job::Kind::load;
    jobs_.push_back(std::move(j));
  }
  wake_.notify_all();
}

void HistoryWriter::show_lesson(std::string trainee, std::string lesson,
                                std::string lesson_hash) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    lesson_trainee_ = std::move(trainee);
    lesson_ = std::move(lesson);
    lesson_hash_ = std::move(lesson_hash);
    for (const Job& j : jobs_)
      if (j.kind == Job::Kind::load) return;
    Job j;
    j.kind = Job::Kind::load;
    jobs_.push_back(std::move(j));
  }
  wake_.notify_all();
}

bool HistoryWriter::poll(std::vector<Outcome>& out) {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (outcomes_.empty()) return false;
  for (Outcome& o : outcomes_) out.push_back(std::move(o));
  outcomes_.clear();
  return true;
}

std::shared_ptr<const ui::HistoryView> HistoryWriter::view() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return view_;
}

void HistoryWriter::wait_idle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [&] { return jobs_.empty() && !busy_; });
}

void HistoryWriter::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [&] { return stopping_ || !jobs_.empty(); });
    if (jobs_.empty()) break;  // stopping, with nothing left to write
    Job job = std::move(jobs_.front());
    jobs_.pop_front();
    busy_ = true;
    lock.unlock();
    if (job.kind == Job::Kind::write)
      write(job);
    else
      load();
    lock.lock();
    busy_ = false;
    if (jobs_.empty()) idle_.notify_all();
  }
  busy_ = false;
  idle_.notify_all();
}

history::HistoryStore* HistoryWriter::store(std::string& error) {
  if (!store_) store_ = open_(error);
  return store_.get();
}

void HistoryWriter::write(Job& job) {
  Outcome o;
  o.trainee = job.record.trainee;
  o.scenario = job.record.scenario;
  o.lesson_attempt = job.attempt.has_value();
  std::string error;
  bool hashed = true;
  if (!job.hash_path.empty()) {
    const auto hash = sha256_file(job.hash_path, error);
    if (hash) job.record.recording_hash = *hash;
    hashed = hash.has_value();
  }
  if (hashed) {
    if (history::HistoryStore* s = store(error))
      o.remembered = (job.attempt ? s->add_attempt(job.record, *job.attempt, error)
                                  : s->add(job.record, error))
                         .has_value();
  }
  if (!o.remembered) o.error = error;
  bool reload = false;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    outcomes_.push_back(std::move(o));
    reload = view_ != nullptr;  // a window that shows the history sees the new row
  }
  if (reload) load();
}

void HistoryWriter::load() {
  std::string file, trainee, scenario, lesson_trainee, lesson, lesson_hash;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    file = file_;
    trainee = trainee_;
    scenario = scenario_;
    lesson_trainee = lesson_trainee_;
    lesson = lesson_;
    lesson_hash = lesson_hash_;
  }
  auto v = std::make_shared<ui::HistoryView>();
  v->loaded = true;
  std::string error;
  std::vector<history::StoredFlight> rows;
  std::error_code ec;
  const bool none_yet = !store_ && !file.empty() && !std::filesystem::exists(file, ec) && !ec;
  if (history::HistoryStore* s = none_yet ? nullptr : store(error)) {
    if (s->trainees(v->trainees, error) && !trainee.empty() && !scenario.empty()) {
      history::Query q;
      q.trainee = trainee;
      q.scenario = scenario;
      q.limit = kProgressFlights;
      if (s->query(q, rows, error)) error.clear();
    }
  }
  v->progress = progress_view(rows, trainee, scenario);
  v->progress.error = error;
  // The lesson's progress: none yet (step 1) when the history has none.
  if (!lesson.empty()) {
    ui::LessonProgressView& l = v->lesson;
    l.trainee = lesson_trainee;
    l.lesson = lesson;
    l.lesson_hash = lesson_hash;
    std::string lesson_error;
    std::vector<history::LessonProgress> progress;
    std::vector<history::StoredAttempt> attempts;
    history::HistoryStore* s = none_yet ? nullptr : store(lesson_error);
    if (s && s->lesson_progress(lesson_trainee, progress, lesson_error) &&
        s->lesson_attempts(lesson_trainee, lesson, lesson_hash, attempts, lesson_error))
      lesson_error.clear();
    for (const history::LessonProgress& p : progress)
      if (p.lesson == lesson && p.lesson_hash == lesson_hash) {
        l.step = p.step;
        l.failed_attempts = p.failed_attempts;
      }
    for (const history::StoredAttempt& a : attempts)
      l.attempts.push_back({a.step, a.passed, a.detail, a.skill});
    l.error = lesson_error;
    l.loaded = true;
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  view_ = std::move(v);
}

}  // namespace mixpilot::cli
