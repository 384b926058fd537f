#pragma once
// Fly from here (SPEC §10): a flight taken over at step k of a recorded one — a branch — is
// recorded from its step k on, and its recording names its parent: the parent's path, its
// SHA-256 and k (metadata parent_recording, parent_sha256, parent_step; docs/recording-
// format.md). Replaying a branch flies its parent's replay up to step k, checked against the
// parent step by step; takes the flight over there with the branch's recorded pilot commands
// (Mode::take_over: the score restarts at k); and flies on, checked against the branch. A
// parent that is a branch itself replays its own parent first, the same way.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/modes/mode.hpp"
#include "core/recording/recording.hpp"
#include "core/recording/replay.hpp"

namespace mixpilot {

// A branch's parent as its recording names it.
struct ParentLink {
  std::string path;       // absolute, where it was when the branch was flown
  std::string sha256;     // of the parent file, lowercase hex
  std::int64_t step = 0;  // k: the branch's first step, flown from the parent's state at t_k
};

// How deep branches may nest (a branch of a branch of ...) before a replay gives up.
inline constexpr int kMaxBranchDepth = 64;

// `rec`'s parent link: `link` set for a branch, left empty for any other recording; false with
// "<path>: its parent_step metadata is ..., expected ..." when the link is malformed.
[[nodiscard]] bool parent_link(const RecordingContents& rec, const std::string& path,
                               std::optional<ParentLink>& link, std::string& error);

// Where the parent of the branch at `branch_path` is: its recorded path, or else a file of that
// name beside the branch (a folder of recordings moved as a whole); "" when neither is a file.
std::string find_parent(const ParentLink& link, const std::string& branch_path);

// The replay of the branch `rec` (at `path`, whose parent is `link`), as replay_mode() makes
// it: nullptr with the reason, which names the parent when it is missing, has changed since the
// branch was flown (its SHA-256), cannot be read or replayed, holds fewer steps than k, or
// flies another scenario or assistance. A branch replays as long as it was flown: `duration`
// is refused.
std::unique_ptr<Mode> branch_replay_mode(const RecordingContents& rec, const std::string& path,
                                         const ParentLink& link, const std::string& scenario_text,
                                         const std::string& source,
                                         std::optional<double> duration, int depth,
                                         std::string& error);

// A branch's replay: its parent's replay flies steps 0 … k − 1, each checked against the parent
// recording; then the branch's own mode takes the flight over from the parent's snapshot at k
// and flies the rest. Seen from outside it is one flight of the scenario (telemetry of every
// step, the branch's metrics, scored on its own steps). step() allocates nothing: the snapshot
// of step k is sized when the replay is made.
class BranchReplay final : public Mode {
 public:
  // `parent`: the parent's replay at step 0; `parent_rec`: its recording (kept here, to check
  // it); `branch`: a fresh mode of the same scenario flying the branch's recorded commands.
  BranchReplay(std::unique_ptr<Mode> parent, RecordingContents parent_rec, std::string parent_path,
               std::int64_t k, std::unique_ptr<Mode> branch);
  BranchReplay(const BranchReplay&) = delete;  // the check points into the parent's recording
  BranchReplay& operator=(const BranchReplay&) = delete;

  ModeKind kind() const override { return branch_->kind(); }
  const std::string& scenario_name() const override { return branch_->scenario_name(); }
  double dt() const override { return branch_->dt(); }
  std::int64_t steps_total() const override { return branch_->steps_total(); }
  std::int64_t steps_done() const override { return flying().steps_done(); }
  [[nodiscard]] bool step() override;
  bool finished() const override { return !failure_.empty() || (taken_ && branch_->finished()); }
  bool lost() const override { return flying().lost(); }
  double lost_at() const override { return flying().lost_at(); }
  const Telemetry& telemetry() const override { return flying().telemetry(); }
  // The branch's: scored on its own steps, from the take-over on.
  Metrics metrics() const override { return branch_->metrics(); }
  Metrics replayed_metrics(const std::vector<double>& recorded_solve_us) const override {
    return branch_->replayed_metrics(recorded_solve_us);
  }
  ModeView view() const override { return branch_->view(); }
  ModeIdentity identity() const override { return branch_->identity(); }
  std::string summary() const override;
  void set_deadline_us(double deadline_us) override {
    parent_->set_deadline_us(deadline_us);
    branch_->set_deadline_us(deadline_us);
  }

  std::int64_t take_over_step() const { return k_; }
  const std::string& parent_path() const { return parent_path_; }
  // What went wrong with the parent's part: a step that differs from the parent recording (at
  // any depth), the parent ending before k, or the take-over refused ("" when nothing did).
  std::string parent_difference() const;

 protected:
  // The mode flying saves; a state of a step before k goes back into the parent's replay, one
  // from k on into the branch's.
  void save_state(std::unique_ptr<ModeSnapshot::State>& state) const override;
  [[nodiscard]] RestoreStatus restore_state(const ModeSnapshot::State& state) override;

 private:
  const Mode& flying() const { return taken_ ? *branch_ : *parent_; }

  std::unique_ptr<Mode> parent_;
  RecordingContents parent_rec_;
  ReplayCheck parent_check_;
  std::string parent_path_;
  std::int64_t k_ = 0;
  std::unique_ptr<Mode> branch_;
  ModeSnapshot at_k_;  // the parent's flight at k, sized when made
  bool taken_ = false;
  std::string failure_;  // why the replay stopped before the branch's end ("" none)
};

// A branch's replay's parent_difference() ("" for any other mode).
std::string parent_difference(const Mode& mode);

}  // namespace mixpilot
