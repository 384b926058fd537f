#include "core/recording/branch_replay.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "core/base/content_hash.hpp"
#include "core/base/input_file.hpp"

namespace mixpilot {

namespace {

namespace fs = std::filesystem;

bool is_sha256_hex(const std::string& s) {
  if (s.size() != 64) return false;
  for (char c : s)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

bool is_file(const std::string& path) {
  std::error_code ec;
  return !path.empty() && fs::is_regular_file(path, ec);
}

// "a branch of /x/p.mcap (taken over at t = 10.005 s, step 667)"
std::string branch_of(const ParentLink& link, double dt) {
  char at[96];
  std::snprintf(at, sizeof at, " (taken over at t = %.3f s, step %lld)", double(link.step) * dt,
                static_cast<long long>(link.step));
  return "a branch of " + escape_controls(link.path) + at;
}

}  // namespace

bool parent_link(const RecordingContents& rec, const std::string& path,
                 std::optional<ParentLink>& link, std::string& error) {
  link.reset();
  const auto value = [&rec](const char* key) -> const std::string* {
    const auto it = rec.metadata.find(key);
    return it == rec.metadata.end() ? nullptr : &it->second;
  };
  const std::string* parent = value("parent_recording");
  const std::string* sha = value("parent_sha256");
  const std::string* step = value("parent_step");
  if (!parent && !sha && !step) return true;
  if (!parent || !sha || !step) {
    error = path + ": its metadata names a parent only in part (parent_recording, parent_sha256 " +
            "and parent_step go together)";
    return false;
  }
  if (parent->empty() || parent->front() != '/') {
    error = path + ": its parent_recording metadata is '" + printable(*parent) +
            "', expected the parent recording's absolute path";
    return false;
  }
  if (!is_sha256_hex(*sha)) {
    error = path + ": its parent_sha256 metadata is '" + printable(*sha) +
            "', expected the parent's SHA-256 (64 lowercase hex digits)";
    return false;
  }
  char* end = nullptr;
  const long long k = std::strtoll(step->c_str(), &end, 10);
  if (step->empty() || *end != '\0' || (*step)[0] == '-' || (*step)[0] == '+' || k < 0 ||
      k > (1ll << 40)) {
    error = path + ": its parent_step metadata is '" + printable(*step) +
            "', expected the step number the branch was taken over at (0 or more)";
    return false;
  }
  link = ParentLink{*parent, *sha, k};
  return true;
}

std::string find_parent(const ParentLink& link, const std::string& branch_path) {
  if (is_file(link.path)) return link.path;
  const fs::path beside = fs::path(branch_path).parent_path() / fs::path(link.path).filename();
  return is_file(beside.string()) ? beside.string() : std::string();
}

std::unique_ptr<Mode> branch_replay_mode(const RecordingContents& rec, const std::string& path,
                                         const ParentLink& link, const std::string& text,
                                         const std::string& source,
                                         std::optional<double> duration, int depth,
                                         std::string& error) {
  const double dt = rec.control_period_ns > 0 ? 1e-9 * double(rec.control_period_ns) : 0.0;
  const std::string what = path + " is " + branch_of(link, dt);
  if (duration) {
    error = what + ": a branch replays as long as it was flown (leave out --duration)";
    return nullptr;
  }
  if (depth >= kMaxBranchDepth) {
    error = what + ": its parents are nested more than " + std::to_string(kMaxBranchDepth) +
            " deep";
    return nullptr;
  }
  if (!rec.states.empty() && std::int64_t(rec.states.front().step) != link.step) {
    error = path + ": its first recorded step is " + std::to_string(rec.states.front().step) +
            ", its parent_step metadata says " + std::to_string(link.step);
    return nullptr;
  }
  const std::string parent_path = find_parent(link, path);
  if (parent_path.empty()) {
    error = what + ", which is missing (nor is there a " +
            escape_controls(fs::path(link.path).filename().string()) + " beside " + path +
            "): a branch is replayed from its parent's flight up to the take-over; put the "
            "parent back";
    return nullptr;
  }
  std::optional<RecordingContents> parent = read_recording(parent_path, error);
  if (!parent) {
    error = what + ", which cannot be read: " + error;
    return nullptr;
  }
  const std::optional<std::string> sha = sha256_file(parent_path, error);
  if (!sha) {
    error = what + ", which cannot be read: " + error;
    return nullptr;
  }
  if (*sha != link.sha256) {
    error = what + ", which has changed since the branch was flown (SHA-256 " + link.sha256 +
            " expected, " + *sha + " found" +
            (parent_path != link.path ? " in " + escape_controls(parent_path) : "") +
            "): a branch replays only from the very flight it was taken over from";
    return nullptr;
  }
  const auto embedded = rec.metadata.find("scenario");
  const auto parent_embedded = parent->metadata.find("scenario");
  if (embedded == rec.metadata.end() || parent_embedded == parent->metadata.end() ||
      embedded->second != parent_embedded->second) {
    error = what + ", whose embedded scenario differs from the branch's: it is not the flight "
                   "the branch was taken over from";
    return nullptr;
  }
  const std::optional<Assistance> assist = recorded_assistance(rec, path, error);
  const std::optional<Assistance> parent_assist =
      assist ? recorded_assistance(*parent, parent_path, error) : std::nullopt;
  if (!assist || !parent_assist) return nullptr;
  if (*assist != *parent_assist) {
    error = what + ", which was flown " +
            (*parent_assist == Assistance::on ? "assisted" : "as a probe") + ", the branch " +
            (*assist == Assistance::on ? "assisted" : "as a probe") +
            ": a branch flies on as its parent flew";
    return nullptr;
  }
  const std::int64_t parent_steps =
      first_recorded_step(*parent) + std::int64_t(parent->pilot.size());
  if (parent_steps < link.step) {
    error = what + ", which holds " + std::to_string(parent_steps) +
            " steps: too few to reach the take-over";
    return nullptr;
  }
  // The parent's replay flies the branch's scenario (the same text, checked above, unless the
  // caller gave another with --allow-mismatch): one flight of one scenario.
  std::unique_ptr<Mode> parent_mode =
      replay_mode(*parent, parent_path, text, source, std::nullopt, error, depth + 1);
  if (!parent_mode) {
    error = what + ": its parent cannot be replayed: " + error;
    return nullptr;
  }
  std::unique_ptr<Mode> branch =
      replay_own_steps(rec, path, text, source, std::nullopt, *assist, error);
  if (!branch) return nullptr;
  if (branch->steps_total() != parent_mode->steps_total()) {
    error = what + ": the branch's flight is planned " + std::to_string(branch->steps_total()) +
            " steps long, its parent's " + std::to_string(parent_mode->steps_total());
    return nullptr;
  }
  const std::int64_t recorded = link.step + std::int64_t(rec.pilot.size());
  auto mode = std::make_unique<BranchReplay>(std::move(parent_mode), std::move(*parent),
                                             parent_path, link.step, std::move(branch));
  mode->stop_after(recorded);
  return mode;
}

BranchReplay::BranchReplay(std::unique_ptr<Mode> parent, RecordingContents parent_rec,
                           std::string parent_path, std::int64_t k, std::unique_ptr<Mode> branch)
    : parent_(std::move(parent)),
      parent_rec_(std::move(parent_rec)),
      parent_check_(parent_rec_),
      parent_path_(std::move(parent_path)),
      k_(k),
      branch_(std::move(branch)) {
  parent_->save(at_k_);  // sizes the snapshot: the take-over in step() allocates nothing
}

bool BranchReplay::step() {
  if (!failure_.empty() || stopped_at(steps_done())) return false;
  if (!taken_) {
    if (parent_->steps_done() < k_) {
      pace_like_this(*parent_);
      if (!parent_->step()) {
        failure_ = "the parent's replay ended at step " + std::to_string(parent_->steps_done()) +
                   ", before the take-over at step " + std::to_string(k_);
        return false;
      }
      parent_check_.on_sample(parent_->telemetry());
      return true;
    }
    parent_->save(at_k_);
    if (const RestoreStatus r = branch_->take_over(at_k_); r != RestoreStatus::ok) {
      failure_ = std::string("the take-over at step ") + std::to_string(k_) +
                 " was refused: " + to_string(r);
      return false;
    }
    taken_ = true;
  }
  pace_like_this(*branch_);
  return branch_->step();
}

std::string BranchReplay::parent_difference() const {
  std::string d = parent_check_.difference_so_far();
  if (!d.empty()) return d + " in the parent " + escape_controls(parent_path_);
  d = mixpilot::parent_difference(*parent_);
  if (!d.empty()) return d;
  return failure_;
}

std::string BranchReplay::summary() const {
  char line[160];
  std::snprintf(line, sizeof line, "  taken over at t = %.3f s (step %lld) from ",
                double(k_) * dt(), static_cast<long long>(k_));
  return branch_->summary() + line + escape_controls(parent_path_) +
         ": scored from there on\n";
}

void BranchReplay::save_state(std::unique_ptr<ModeSnapshot::State>& state) const {
  save_state_of(flying(), state);
}

RestoreStatus BranchReplay::restore_state(const ModeSnapshot::State& state) {
  // Both are the same scenario's flights with recorded pilots, which continue from any state.
  if (const RestoreStatus r = restore_state_of(*branch_, state); r != RestoreStatus::ok) return r;
  if (branch_->steps_done() >= k_) {
    taken_ = true;
  } else {
    if (const RestoreStatus r = restore_state_of(*parent_, state); r != RestoreStatus::ok)
      return r;
    taken_ = false;
  }
  failure_.clear();
  return RestoreStatus::ok;
}

std::string parent_difference(const Mode& mode) {
  const auto* branch = dynamic_cast<const BranchReplay*>(&mode);
  return branch ? branch->parent_difference() : std::string();
}

}  // namespace mixpilot
