#pragma once
// The instructor's side of the network (SPEC §10): the stations it discovers from their
// announcements (rt/mixpilot/station), each station's telemetry (rt/mixpilot/pose and lambda,
// told apart by the writers' station tag, input/net/telemetry_publisher.hpp), and the commands
// it sends (rt/mixpilot/instructor/command). `mixpilot instruct` is built on it, and so can a
// window be: poll() reads what has arrived (from any one thread), stations() is a copy.
//
// With DDS Security (the process's, or Options::security) the participant authenticates with
// an instructor's identity; a station's DDS refuses the command writer of an identity whose
// permissions do not allow it, before anything is sent (open() says so).
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/modes/instructor.hpp"
#include "input/net/dds.hpp"
#include "input/net/instructor_checks.hpp"
#include "input/net/instructor_link.hpp"

namespace mixpilot::net {

struct CommandResultView {
  std::string issuer;
  std::uint64_t sequence = 0;
  std::int64_t issued_ns = 0;
  CommandRefusal result = CommandRefusal::none;
};

struct StationView {
  std::string station, trainee, scenario, mode;
  StationState state = StationState::ready;
  double t = 0, duration = 0, lambda = 0, deviation = 0, time_in_ball = 0, mean_lambda = 0;
  InstructorInForce in_force;  // what the instructor's commands keep in force at t
  bool accepts_instructor = false;
  CommandSecurity security = CommandSecurity::no_instructor;
  std::uint64_t accepted = 0;
  std::array<std::uint64_t, kCommandRefusals> refused{};  // by CommandRefusal
  std::string last_refusal;                                // the newest in words
  std::uint64_t security_refused = 0;
  std::string security_last;
  std::vector<CommandResultView> recent;  // newest last
  std::uint64_t announcements = 0;        // heard by this client
  std::int64_t heard_ns = 0;              // system clock of the newest
  // Its telemetry heard by this client.
  std::uint64_t poses = 0, lambdas = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // the pose's attitude
  double telemetry_lambda = 0;
  std::uint64_t refused_total() const;
};

class InstructorClient {
 public:
  struct Options {
    std::uint32_t domain = 0;
    std::string issuer;  // who commands (1 to 63 bytes of printable UTF-8)
    // Authenticate with these (else the process's, use_security()).
    const SecurityFiles* security = nullptr;
    bool command = true;  // create the command writer (false: only watch)
  };

  InstructorClient() = default;
  InstructorClient(const InstructorClient&) = delete;
  InstructorClient& operator=(const InstructorClient&) = delete;

  // Joins the domain: readers of the announcements and telemetry, and the command writer.
  [[nodiscard]] bool open(const Options& options, std::string& error);
  // Reads what has arrived, waiting up to `seconds` for something.
  void poll(double seconds);
  std::vector<StationView> stations() const;
  std::optional<StationView> station(const std::string& name) const;
  // The stations' command readers this writer is matched with (DDS Security: only those that
  // authenticated it and whose permissions and governance agree).
  std::uint32_t matched() const;
  // Whether `station`'s command reader is among them (its announcement's participant).
  bool matched(const std::string& station) const;

  // The next sequence number: above the last one sent and the system clock's microseconds, so
  // a new process of the same issuer continues above an earlier one's.
  std::uint64_t next_sequence();
  // Sends `c` to `station` numbered `sequence`, issued now (or at `issued_ns`).
  [[nodiscard]] bool send(const std::string& station, const InstructorCommand& c,
                          std::uint64_t sequence, std::string& error,
                          std::optional<std::int64_t> issued_ns = std::nullopt);
  // Sends raw fields, as given (tests: values a checked command never has).
  [[nodiscard]] bool send_fields(const InstructorFields& f, std::string& error);
  // What `station` announced of this issuer's command `sequence` (the newest so numbered; the
  // one issued at `issued_ns` when given, so an earlier command of the same number, such as
  // the original of a replay, is not taken for it), once it has.
  std::optional<CommandRefusal> result(const std::string& station, std::uint64_t sequence,
                                       std::optional<std::int64_t> issued_ns = std::nullopt) const;
  // The issue time of the newest command sent.
  std::int64_t last_issued_ns() const { return last_issued_ns_; }

  const Options& options() const { return options_; }

 private:
  void read_status();
  void read_telemetry();
  std::string station_of_writer(std::int32_t reader, std::uint64_t handle);

  Options options_;
  Participant participant_;
  std::int32_t status_reader_ = 0, pose_reader_ = 0, lambda_reader_ = 0, writer_ = 0;
  std::int32_t waitset_ = 0;
  std::map<std::string, StationView> stations_;
  std::map<std::uint64_t, std::string> writers_;  // publication handle → station
  std::map<std::string, std::array<unsigned char, 16>> participants_;  // station → its participant
  std::uint64_t last_sequence_ = 0;
  std::int64_t last_issued_ns_ = 0;
};

// The command in words: "ceiling 0.3", "gust (2, 0, 0) N for 0.5 s", "marker \"text\"", ...
std::string describe(const InstructorCommand& c);

}  // namespace mixpilot::net
