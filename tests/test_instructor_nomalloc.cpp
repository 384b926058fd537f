// The instructor's commands are taken and applied on the control thread without allocating
// (SPEC §8's real-time rule): the session drains its inbox between steps, hands each command to
// the mode (bounds, gust, extra delay, input loss, marker) and steps, all inside a NoMalloc
// scope, with the engine built with Eigen's allocation check armed.
#include <gtest/gtest.h>

#include <string>

#include "core/modes/command_inbox.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/session.hpp"
#include "no_malloc.hpp"

namespace mixpilot {
namespace {

TEST(Instructor, InboxDrainsAndAppliesWithoutAllocating) {
  ModeRequest r;
  r.pilot_name = "novice";
  r.duration = 2.0;
  std::string error;
  auto mode = load_mode(std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml",
                        std::move(r), error);
  ASSERT_TRUE(mode) << error;
  CommandInbox inbox;
  Session session(*mode);
  session.set_inbox(&inbox);
  ASSERT_TRUE(session.step());  // the first step sizes nothing more, but warms the caches

  InstructorCommand bounds, gust, delay, loss, marker;
  bounds.kind = InstructorCommandKind::bounds;
  bounds.bounds = {0.1, 0.3};
  gust.kind = InstructorCommandKind::gust;
  gust.force = Eigen::Vector3d(2.0, -1.0, 0.5);
  gust.duration = 0.5;
  delay.kind = InstructorCommandKind::extra_delay;
  delay.delay = 0.03;
  loss.kind = InstructorCommandKind::input_loss;
  loss.duration = 0.3;
  marker.kind = InstructorCommandKind::marker;
  marker.text.assign("no allocation here");
  for (const InstructorCommand& c : {bounds, gust, delay, loss, marker}) ASSERT_TRUE(inbox.push(c));

  long allocations = 0;
  int with_commands = 0;
  for (int i = 0; i < 60; ++i) {
    {
      NoMalloc guard;
      ASSERT_TRUE(session.step());
      allocations += NoMalloc::count();
    }
    with_commands += mode->telemetry().num_commands;
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(with_commands, 5);
  EXPECT_EQ(inbox.applied(), 5);
}

}  // namespace
}  // namespace mixpilot
