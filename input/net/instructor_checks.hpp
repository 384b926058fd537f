#pragma once
// What a station checks in every instructor command before it reaches the control thread
// (SPEC §10, docs/instructor-security.md). No DDS here: the station's link hands the fields over
// with the time the command arrived on the station's clock, so tests check with any clock.
//
// A command addressed to this station is taken only when
//  - the station obeys an instructor (`fly --instructor`) and the command came over DDS Security,
//    or unauthenticated commands were allowed explicitly on a loopback-only configuration;
//  - every number is finite and the kind's fields are in range: 0 ≤ floor ≤ ceiling ≤ 1; a gust
//    of at most kMaxForce newtons for 0 < duration ≤ kMaxDuration seconds; an input loss for
//    0 < duration ≤ kMaxDuration; an extra delay 0 ≤ delay ≤ kMaxDelay; a marker of 1 to
//    DebriefNote::kCapacity bytes of UTF-8 without control characters; an issuer name of 1 to
//    63 bytes of the same;
//  - it was issued no longer than max_age_s ago and no more than clock_tolerance_s ahead of
//    this station's clock (stale otherwise);
//  - its sequence number is above the last one taken from its issuer (a replay otherwise).
// Refusals are counted by reason, the newest kept in words.
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/modes/instructor.hpp"
#include "input/net/note_log.hpp"

namespace mixpilot::net {

enum class CommandRefusal : std::uint8_t {
  none = 0,             // taken
  not_allowed = 1,      // this station obeys no instructor
  unauthenticated = 2,  // no DDS Security, and unauthenticated commands were not allowed
  bad_value = 3,        // an unknown kind, a number not finite or out of range, a bad text
  stale = 4,            // issued too long ago, or ahead of this station's clock
  replayed = 5,         // a sequence number not above the last one taken from its issuer
  busy = 6,             // the control thread's ring is full, or too many issuers at once
};
inline constexpr int kCommandRefusals = 7;  // reasons, none included
// "accepted", "instructor not allowed", "unauthenticated", "bad value", "stale", "replayed",
// "busy".
const char* to_string(CommandRefusal r);

// Bounds of what an instructor may ask for.
inline constexpr double kMaxForce = 20.0;     // [N] a gust: about 1.5 g on the MikroKopter
inline constexpr double kMaxDuration = 10.0;  // [s] a gust or an input loss
inline constexpr double kMaxDelay = 0.5;      // [s] extra round-trip delay
inline constexpr std::size_t kMaxIssuer = 63;  // bytes of an issuer's name (the IDL's bound)

struct InstructorFields {
  std::string_view station, issuer, text;
  std::uint64_t sequence = 0;
  std::int64_t issued_ns = 0;  // the instructor's system clock
  std::uint8_t kind = 0;
  double floor = 0, ceiling = 1;
  std::array<double, 3> force{};
  double duration = 0, delay = 0;
};

// Why one command was refused: `format` is a string literal taking a, b and c (doubles).
struct RefusalNote {
  CommandRefusal why = CommandRefusal::none;
  const char* format = "";
  double a = 0, b = 0, c = 0;
};
// "<reason>: <what>" into `out` (at most `size` bytes, always terminated). Allocates nothing.
void describe(const RefusalNote& note, char* out, std::size_t size);

// Whether `s` is valid UTF-8 without control characters (C0, DEL, C1).
bool printable_utf8(std::string_view s);

class InstructorCheck {
 public:
  static constexpr int kMaxIssuers = 32;
  struct Limits {
    double max_age_s = 5.0;           // issued longer ago: stale
    double clock_tolerance_s = 0.5;   // issued further ahead of this clock: stale
  };
  void setup(const Limits& limits);
  // Checks the content, age and order of a command this station may obey, arrived at `now`
  // (this station's system clock [ns]). When it passes (none) it is taken into `out` (only the
  // kind's own fields; the others keep their defaults) and its sequence remembered.
  [[nodiscard]] CommandRefusal check(const InstructorFields& c, std::int64_t now,
                                     InstructorCommand& out, RefusalNote& note);

 private:
  struct Issuer {
    std::array<char, kMaxIssuer + 1> name{};
    std::size_t size = 0;
    std::uint64_t last_sequence = 0;
    std::int64_t last_ns = 0;  // when its last command was taken (this clock)
    bool used = false;
  };
  Limits limits_;
  std::array<Issuer, kMaxIssuers> issuers_{};
};

// The refusals of one station (input/net/note_log.hpp).
using RefusalLog = NoteLog<RefusalNote, kCommandRefusals>;

}  // namespace mixpilot::net
