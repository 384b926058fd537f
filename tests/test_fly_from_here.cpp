// Fly from here (SPEC §10) in the engine: Mode::take_over against Mode::restore, the emulated
// pilot's cold start, a branch scored on its own steps, and a branch's recording replayed from
// its parent bit for bit (core/recording/branch_replay.hpp) — at any depth, as a probe, with its
// parent moved beside it — while a missing, changed or foreign parent is refused with its name.
// The take-over and the steps after it allocate nothing: every malloc is counted (no_malloc.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/content_hash.hpp"
#include "core/base/input_file.hpp"
#include "core/control/pilot_emulated.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/modes/report.hpp"
#include "core/modes/session.hpp"
#include "core/recording/branch_replay.hpp"
#include "core/recording/replay.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "no_malloc.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;

const std::string kHelix = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml";

std::string helix_text() {
  std::string text, error;
  EXPECT_TRUE(read_text_file(kHelix, text, error)) << error;
  return text;
}

// A flight of mi_helix, `seconds` long, flown by the scenario's pilot `pilot` or by `source`.
std::unique_ptr<Mode> helix(const std::string& pilot, double seconds,
                            Assistance assist = Assistance::on,
                            std::unique_ptr<PilotSource> source = nullptr) {
  ModeRequest request;
  request.duration = seconds;
  request.pilot_name = pilot;
  request.pilot_source = std::move(source);
  request.assist = assist;
  std::string error;
  std::unique_ptr<Mode> mode = make_mode(helix_text(), kHelix, std::move(request), error);
  EXPECT_TRUE(mode) << error;
  return mode;
}

std::unique_ptr<PilotSource> emulated(const std::string& name) {
  std::string error;
  const std::optional<Scenario> scenario = parse_scenario(helix_text(), kHelix, error);
  EXPECT_TRUE(scenario) << error;
  std::unique_ptr<PilotSource> pilot = make_scenario_pilot(*scenario, name, error);
  EXPECT_TRUE(pilot) << error;
  return pilot;
}

// Flies `mode` on to its end, recording it at `path` (a branch names `parent` when given); saves
// the flight into `at_k` before step k when asked.
void record_to_end(Mode& mode, const std::string& path, const std::optional<ParentLink>& parent,
                   Assistance assist = Assistance::on, std::int64_t k = -1,
                   ModeSnapshot* at_k = nullptr) {
  SessionInfo info{to_string(mode.kind()), helix_text(), kHelix, 1, mode.identity().pilot};
  info.assist = assist == Assistance::on ? "on" : "off";
  if (parent) {
    info.parent_recording = parent->path;
    info.parent_sha256 = parent->sha256;
    info.parent_step = parent->step;
  }
  RecordingSink sink;
  std::string error;
  ASSERT_TRUE(sink.open(path, mode, info, error)) << error;
  Session session(mode);
  session.add_sink(&sink);
  do {
    if (at_k && mode.steps_done() == k) mode.save(*at_k);
  } while (session.step());
  ASSERT_TRUE(sink.close(error)) << error;
}

RecordingContents read(const std::string& path) {
  std::string error;
  std::optional<RecordingContents> rec = read_recording(path, error);
  EXPECT_TRUE(rec) << error;
  return rec ? std::move(*rec) : RecordingContents{};
}

ParentLink link_to(const std::string& parent, std::int64_t k) {
  std::string error;
  const std::optional<std::string> sha = sha256_file(parent, error);
  EXPECT_TRUE(sha) << error;
  return ParentLink{fs::absolute(parent).lexically_normal().string(), sha.value_or(""), k};
}

// A recorded flight of `pilot`, `seconds` long, and its snapshot before step k.
struct Parent {
  std::string path;
  ModeSnapshot at_k;
};
Parent record_parent(const std::string& name, const std::string& pilot, double seconds,
                     std::int64_t k, Assistance assist = Assistance::on) {
  Parent p;
  p.path = test::fresh_path("fly_from_here", name).string();
  std::unique_ptr<Mode> mode = helix(pilot, seconds, assist);
  record_to_end(*mode, p.path, std::nullopt, assist, k, &p.at_k);
  EXPECT_EQ(p.at_k.step(), k);
  return p;
}

// The branch of `parent` flown by `pilot` from its snapshot, recorded at `path`; its metrics.
Metrics record_branch(const Parent& parent, std::int64_t k, const std::string& pilot,
                      double seconds, const std::string& path,
                      Assistance assist = Assistance::on) {
  std::unique_ptr<Mode> branch = helix("", seconds, assist, emulated(pilot));
  EXPECT_EQ(branch->take_over(parent.at_k), RestoreStatus::ok);
  record_to_end(*branch, path, link_to(parent.path, k), assist);
  return with_lost_fields(branch->metrics(), *branch);
}

// Replays the recording at `path` as every front end does: its mode (a branch's replay for a
// branch), checked step by step. "" when every step is as recorded, else what differed; the
// replay's metrics in `metrics`.
std::string replay(const std::string& path, Metrics* metrics = nullptr,
                   std::string* error_out = nullptr) {
  const RecordingContents rec = read(path);
  std::string error;
  std::unique_ptr<Mode> mode =
      replay_mode(rec, path, rec.metadata.at("scenario"), kHelix, std::nullopt, error);
  if (error_out) *error_out = error;
  if (!mode) return "not replayed: " + error;
  ReplayCheck check(rec);
  Session session(*mode);
  session.add_sink(&check);
  session.run();
  if (metrics) *metrics = replay_metrics(*mode, rec);
  if (std::string d = parent_difference(*mode); !d.empty()) return d;
  return check.first_difference(mode->steps_done());
}

double metric(const Metrics& m, const std::string& name) {
  for (const auto& [k, v] : m)
    if (k == name) return v;
  ADD_FAILURE() << "no metric " << name;
  return 0.0;
}

// restore() continues the saved flight with the saved pilot, or refuses; take_over() flies it
// on with another: the experienced pilot cannot continue the novice's reaction delay line, but
// takes the novice's flight over, and its first step starts from the saved state bit for bit.
TEST(FlyFromHere, TakeOverIsNotRestore) {
  constexpr std::int64_t k = 120;
  std::unique_ptr<Mode> novice = helix("novice", 3.0);
  while (novice->steps_done() < k) ASSERT_TRUE(novice->step());
  ModeSnapshot at_k;
  novice->save(at_k);
  ASSERT_TRUE(novice->step());
  const Telemetry novice_k = novice->telemetry();

  std::unique_ptr<Mode> experienced = helix("experienced", 3.0);
  EXPECT_EQ(experienced->restore(at_k), RestoreStatus::pilot);
  EXPECT_EQ(experienced->steps_done(), 0) << "a refused restore changes nothing";
  ASSERT_EQ(experienced->take_over(at_k), RestoreStatus::ok);
  EXPECT_EQ(experienced->steps_done(), k);
  ASSERT_TRUE(experienced->step());
  const Telemetry& s = experienced->telemetry();
  EXPECT_EQ(s.step, k);
  EXPECT_EQ(s.x, novice_k.x) << "step k starts from the saved state";
  EXPECT_EQ(s.lambda, novice_k.lambda) << "λ_k comes from the saved prediction";
  EXPECT_NE(s.pilot.roll, novice_k.pilot.roll) << "another pilot flies step k";
  EXPECT_EQ(experienced->identity().pilot, "experienced");
}

// The emulated pilot that takes over starts as at a flight's start: its NMPC cold-started at
// hover from the state it is given, its reaction delay line full of hover commands. A pilot that
// flew a flight of its own before gives, once taken over, the very commands of a fresh one.
TEST(FlyFromHere, TheEmulatedPilotColdStartsAsAtAFlightsStart) {
  std::unique_ptr<Mode> novice = helix("novice", 3.0);
  std::vector<Eigen::VectorXd> states;
  std::vector<double> times;
  while (novice->step()) {
    states.push_back(novice->telemetry().x);
    times.push_back(novice->telemetry().t);
  }
  for (const char* name : {"novice", "experienced"}) {
    std::unique_ptr<PilotSource> used = emulated(name), fresh = emulated(name);
    PilotCommand c;
    for (std::size_t i = 0; i < 90; ++i) ASSERT_TRUE(used->command(std::int64_t(i), times[i], states[i], c));
    used->take_over();
    for (std::size_t i = 100; i < 140; ++i) {
      PilotCommand a, b;
      ASSERT_TRUE(used->command(std::int64_t(i), times[i], states[i], a));
      ASSERT_TRUE(fresh->command(std::int64_t(i), times[i], states[i], b));
      EXPECT_EQ(a.roll, b.roll) << name << " step " << i;
      EXPECT_EQ(a.pitch, b.pitch) << name << " step " << i;
      EXPECT_EQ(a.rotor_speed, b.rotor_speed) << name << " step " << i;
    }
  }
}

// A branch is scored on its own steps (SPEC §10): its duration is the time flown from the
// take-over, λ's mean and minimum are those of its steps, and its progress is out of the
// waypoints from the take-over on (an experienced pilot flies nearly all of them, more than the
// share of the whole flight left at the take-over).
TEST(FlyFromHere, ABranchIsScoredOnItsOwnSteps) {
  constexpr std::int64_t k = 200;
  constexpr double seconds = 6.0;
  std::unique_ptr<Mode> novice = helix("novice", seconds);
  while (novice->steps_done() < k) ASSERT_TRUE(novice->step());
  ModeSnapshot at_k;
  novice->save(at_k);
  std::unique_ptr<Mode> branch = helix("", seconds, Assistance::on, emulated("experienced"));
  ASSERT_EQ(branch->take_over(at_k), RestoreStatus::ok);
  EXPECT_EQ(metric(branch->metrics(), "duration_s"), 0.0) << "nothing flown yet";
  double sum = 0.0, least = 1.0;
  std::int64_t n = 0;
  while (branch->step()) {
    sum += branch->telemetry().lambda;
    least = std::min(least, branch->telemetry().lambda);
    ++n;
  }
  const std::int64_t total = branch->steps_total();
  ASSERT_EQ(n, total - k);
  const Metrics m = branch->metrics();
  EXPECT_NEAR(metric(m, "duration_s"), double(n) * branch->dt(), 1e-12);
  EXPECT_NEAR(metric(m, "mean_lambda"), sum / double(n), 1e-12);
  EXPECT_EQ(metric(m, "min_lambda"), least);
  EXPECT_GT(metric(m, "progress"), double(total - k) / double(total) + 0.05);
  EXPECT_LE(metric(m, "progress"), 1.0);
}

// What take_over() refuses, as restore() does: another kind, length or assistance, and a mode
// that has no pilot to take anything over.
TEST(FlyFromHere, TakeOverRefusesWhatCannotGoOnAndChangesNothing) {
  std::unique_ptr<Mode> probe = helix("novice", 2.0, Assistance::off);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(probe->step());
  ModeSnapshot of_probe;
  probe->save(of_probe);
  std::unique_ptr<Mode> assisted = helix("experienced", 2.0);
  EXPECT_EQ(assisted->take_over(of_probe), RestoreStatus::assistance);
  EXPECT_EQ(assisted->restore(of_probe), RestoreStatus::assistance);
  EXPECT_EQ(assisted->steps_done(), 0);
  EXPECT_NE(std::string(to_string(RestoreStatus::assistance)), "");
  std::unique_ptr<Mode> longer = helix("experienced", 3.0, Assistance::off);
  EXPECT_EQ(longer->take_over(of_probe), RestoreStatus::other_scenario);
  std::unique_ptr<Mode> probe_too = helix("experienced", 2.0, Assistance::off);
  EXPECT_EQ(probe_too->take_over(of_probe), RestoreStatus::ok);
  ModeSnapshot empty;
  EXPECT_EQ(probe_too->take_over(empty), RestoreStatus::empty);

  std::string error;
  std::unique_ptr<Mode> pendubot = load_mode(
      std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/pendubot_swingup.toml", {}, error);
  ASSERT_TRUE(pendubot) << error;
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(pendubot->step());
  ModeSnapshot of_pendubot;
  pendubot->save(of_pendubot);
  EXPECT_EQ(pendubot->take_over(of_pendubot), RestoreStatus::no_pilot);
  EXPECT_EQ(pendubot->restore(of_pendubot), RestoreStatus::ok) << "restore() is unchanged";
}

// The take-over and every step after it allocate nothing: with the emulated pilot (its NMPC
// cold-started), and in a branch's replay, which takes the flight over inside a step.
TEST(FlyFromHere, NoAllocationInStepAfterTheTakeOver) {
  constexpr std::int64_t k = 100;
  std::unique_ptr<Mode> novice = helix("novice", 2.5);
  while (novice->steps_done() < k) ASSERT_TRUE(novice->step());
  ModeSnapshot at_k;
  novice->save(at_k);
  std::unique_ptr<Mode> branch = helix("", 2.5, Assistance::on, emulated("experienced"));
  {
    NoMalloc guard;
    EXPECT_EQ(branch->take_over(at_k), RestoreStatus::ok);
    EXPECT_EQ(NoMalloc::count(), 0) << "allocations in take_over()";
  }
  const GuardedSteps after = step_to_end_without_malloc(*branch, [] {});
  EXPECT_EQ(after.steps, branch->steps_total() - k);
  EXPECT_EQ(after.allocations, 0) << "allocations in step() after the take-over";

  // A branch's replay: the parent's steps, the take-over at k and the branch's steps.
  const Parent parent = record_parent("alloc_parent.mcap", "novice", 2.5, k);
  const std::string path = test::fresh_path("fly_from_here", "alloc_branch.mcap").string();
  record_branch(parent, k, "experienced", 2.5, path);
  const RecordingContents rec = read(path);
  std::string error;
  std::unique_ptr<Mode> replayed =
      replay_mode(rec, path, rec.metadata.at("scenario"), kHelix, std::nullopt, error);
  ASSERT_TRUE(replayed) << error;
  const GuardedSteps replay_steps = step_to_end_without_malloc(*replayed, [] {});
  EXPECT_EQ(replay_steps.steps, replayed->steps_total());
  EXPECT_EQ(replay_steps.allocations, 0) << "allocations in a branch's replay";
}

// A branch's recording: it names its parent and the take-over step, holds its own steps only,
// the first of them from the parent's state at k; its replay flies the parent to k and the
// branch on, bit for bit, scored as the branch was.
TEST(FlyFromHere, ABranchRecordingReplaysBitForBitFromItsParent) {
  constexpr std::int64_t k = 150;
  constexpr double seconds = 4.0;
  const Parent parent = record_parent("parent.mcap", "novice", seconds, k);
  const std::string path = test::fresh_path("fly_from_here", "branch.mcap").string();
  const Metrics live = record_branch(parent, k, "experienced", seconds, path);
  const RecordingContents rec = read(path), parent_rec = read(parent.path);
  std::optional<ParentLink> link;
  std::string error;
  ASSERT_TRUE(parent_link(rec, path, link, error)) << error;
  ASSERT_TRUE(link);
  EXPECT_EQ(link->path, fs::absolute(parent.path).lexically_normal().string());
  EXPECT_EQ(link->sha256, *sha256_file(parent.path, error));
  EXPECT_EQ(link->step, k);
  EXPECT_EQ(first_recorded_step(rec), k);
  ASSERT_FALSE(rec.states.empty());
  EXPECT_EQ(rec.states.front().step, std::uint64_t(k));
  EXPECT_EQ(rec.states.front().x, parent_rec.states[std::size_t(k)].x)
      << "the branch's first step is the parent's step k";
  EXPECT_EQ(std::int64_t(rec.states.size()), std::int64_t(parent_rec.states.size()) - k);
  EXPECT_EQ(rec.pilot.front().source, "experienced");

  Metrics replayed;
  EXPECT_EQ(replay(path, &replayed), "");
  EXPECT_EQ(replayed, live) << "the replay scores the branch as it was flown";
  EXPECT_EQ(replay(parent.path), "") << "the parent replays as before";
}

// A branch of a branch, taken over after the first take-over and before it (where the first
// branch's replay shows its parent's flight): each replays bit for bit, through every parent.
TEST(FlyFromHere, ABranchOfABranchReplaysThroughEveryParent) {
  constexpr double seconds = 4.0;
  const Parent grandparent = record_parent("grandparent.mcap", "novice", seconds, 100);
  const std::string branch = test::fresh_path("fly_from_here", "first.mcap").string();
  record_branch(grandparent, 100, "experienced", seconds, branch);
  for (const std::int64_t j : {180, 60}) {
    // The first branch's replay, flown to j: its flight there is the new branch's parent.
    const RecordingContents rec = read(branch);
    std::string error;
    std::unique_ptr<Mode> mode =
        replay_mode(rec, branch, rec.metadata.at("scenario"), kHelix, std::nullopt, error);
    ASSERT_TRUE(mode) << error;
    while (mode->steps_done() < j) ASSERT_TRUE(mode->step());
    Parent p{branch, {}};
    mode->save(p.at_k);
    const std::string second =
        test::fresh_path("fly_from_here", "second_" + std::to_string(j) + ".mcap").string();
    record_branch(p, j, "novice", seconds, second);
    EXPECT_EQ(replay(second), "") << "taken over at step " << j;
  }
}

// A probe is flown on as a probe: its branch replays as one; an assisted branch of a probe is
// no branch of it.
TEST(FlyFromHere, AProbesBranchIsAProbe) {
  constexpr std::int64_t k = 90;
  const Parent parent = record_parent("probe.mcap", "novice", 3.0, k, Assistance::off);
  const std::string path = test::fresh_path("fly_from_here", "probe_branch.mcap").string();
  const Metrics live = record_branch(parent, k, "experienced", 3.0, path, Assistance::off);
  Metrics replayed;
  EXPECT_EQ(replay(path, &replayed), "");
  EXPECT_EQ(replayed, live);
  std::unique_ptr<Mode> assisted = helix("experienced", 3.0);
  EXPECT_EQ(assisted->take_over(parent.at_k), RestoreStatus::assistance);
}

// Without its parent a branch cannot be replayed, and says which parent it needs: missing (its
// recorded path and the file name beside the branch both tried), changed since (both hashes),
// or moved beside the branch (found there). A malformed link and --duration are refused too.
TEST(FlyFromHere, AMissingOrChangedParentIsAClearError) {
  constexpr std::int64_t k = 80;
  const Parent parent = record_parent("lost_parent.mcap", "novice", 2.0, k);
  const std::string path = test::fresh_path("fly_from_here", "orphan.mcap").string();
  record_branch(parent, k, "experienced", 2.0, path);
  const std::string abs = fs::absolute(parent.path).lexically_normal().string();
  std::string error;

  // Moved away: missing.
  const fs::path away = fs::path(parent.path).parent_path() / "elsewhere";
  fs::create_directories(away);
  fs::rename(parent.path, away / "lost_parent.mcap");
  EXPECT_NE(replay(path, nullptr, &error), "");
  EXPECT_NE(error.find(path + " is a branch of " + abs), std::string::npos) << error;
  EXPECT_NE(error.find("step 80"), std::string::npos) << error;
  EXPECT_NE(error.find("which is missing"), std::string::npos) << error;

  // The branch moved with its parent: found beside it.
  const std::string moved = (away / "orphan.mcap").string();
  fs::copy_file(path, moved);
  EXPECT_EQ(replay(moved), "");
  fs::rename(away / "lost_parent.mcap", parent.path);
  EXPECT_EQ(replay(path), "");

  // Another flight at the parent's path: changed.
  std::unique_ptr<Mode> other = helix("experienced", 2.0);
  record_to_end(*other, parent.path + ".new.mcap", std::nullopt);
  fs::rename(parent.path + ".new.mcap", parent.path);
  EXPECT_NE(replay(path, nullptr, &error), "");
  EXPECT_NE(error.find(path + " is a branch of " + abs), std::string::npos) << error;
  EXPECT_NE(error.find("has changed since the branch was flown"), std::string::npos) << error;
  EXPECT_NE(error.find(read(path).metadata.at("parent_sha256") + " expected"), std::string::npos)
      << error;
  EXPECT_NE(error.find(*sha256_file(parent.path, error) + " found"), std::string::npos) << error;

  // Not a recording at all.
  std::ofstream(parent.path, std::ios::trunc) << "not an MCAP file";
  EXPECT_NE(replay(path, nullptr, &error), "");
  EXPECT_NE(error.find("which cannot be read: " + parent.path), std::string::npos) << error;

  // A malformed link.
  RecordingContents rec = read(path);
  rec.metadata["parent_step"] = "-3";
  std::optional<ParentLink> link;
  EXPECT_FALSE(parent_link(rec, "b.mcap", link, error));
  EXPECT_NE(error.find("b.mcap: its parent_step metadata is '-3'"), std::string::npos) << error;
  rec.metadata.erase("parent_sha256");
  EXPECT_FALSE(parent_link(rec, "b.mcap", link, error));
  EXPECT_NE(error.find("names a parent only in part"), std::string::npos) << error;
  // --duration.
  const RecordingContents branch_rec = read(path);
  EXPECT_FALSE(replay_mode(branch_rec, path, branch_rec.metadata.at("scenario"), kHelix, 1.0, error));
  EXPECT_NE(error.find("a branch replays as long as it was flown"), std::string::npos) << error;
}

}  // namespace
}  // namespace mixpilot
