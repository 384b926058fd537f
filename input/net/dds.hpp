#pragma once
// Cyclone DDS for mixpilot's network peers (SPEC §9): a participant in a domain, and the check
// that the configuration in force keeps traffic on this machine. Cyclone reads its
// configuration from CYCLONEDDS_URI; without one it discovers peers by multicast on every
// interface, which tests, demos and CI must never do (assets/dds-loopback.xml).
#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace mixpilot::net {

// Whether CYCLONEDDS_URI names a configuration that keeps DDS on loopback: interface `lo`,
// multicast off, the peer 127.0.0.1. `why` says what is missing otherwise.
[[nodiscard]] bool loopback_only(std::string& why);

// The project's loopback configuration, as a CYCLONEDDS_URI value.
std::string loopback_config_uri();

// Nothing leaves this machine unless the user configures DDS: without CYCLONEDDS_URI, sets it
// to the loopback configuration (before the first participant is created).
void use_loopback_unless_configured();

// --- DDS Security (docs/instructor-security.md) ----------------------------------------------

// One identity's DDS Security files, from the folder `--dds-security FOLDER` names (as
// mixpilot-security-ca, packaging/dds-security-ca.sh, makes them): identity_ca.pem, cert.pem, key.pem,
// permissions_ca.pem, governance.p7s, permissions.p7s. Paths absolute.
struct SecurityFiles {
  std::string folder;
  std::string identity_ca, certificate, private_key, permissions_ca, governance, permissions;
};
// The files of `folder`, each checked to exist and be readable; nullopt with the reason.
[[nodiscard]] std::optional<SecurityFiles> security_files(const std::string& folder,
                                                          std::string& error);
// Every participant this process opens from now on authenticates with `files` (Cyclone's
// builtin plugins: Debian's /usr/lib/x86_64-linux-gnu/libddsc0debian/libdds_security_*.so).
void use_security(const SecurityFiles& files);
// The process's security files (use_security), or nullptr.
const SecurityFiles* process_security();
// Whether CYCLONEDDS_URI's configuration holds a Security (or DDSSecurity) section.
bool security_in_config();
// Either: the participants of this process authenticate.
inline bool security_configured() { return process_security() || security_in_config(); }

// What DDS Security refused of the peers, as Cyclone logs it (a process-wide log sink counts
// failed authentication handshakes and endpoints refused for security; a refused peer retries
// about once a second, so this counts attempts). The newest in words.
struct SecurityLog {
  std::uint64_t refused = 0;
  std::string last;
};
SecurityLog security_log();
// Cyclone's log goes through mixpilot's sink from now on (once per process): the security
// refusals above are counted (the first of each kind printed on stderr), everything else is
// printed as Cyclone would.
void install_log_sink();

// A domain participant; deleting it deletes every reader, writer and topic it made.
class Participant {
 public:
  Participant() = default;
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  // Joins `domain`; with `security` (else the process's, use_security()) it authenticates.
  [[nodiscard]] bool open(std::uint32_t domain, std::string& error,
                          const SecurityFiles* security = nullptr);
  void close();
  std::int32_t handle() const { return handle_; }  // dds_entity_t
  std::uint32_t domain() const { return domain_; }

 private:
  std::int32_t handle_ = 0;
  std::uint32_t domain_ = 0;
};

// The writers heard on a topic (their publication handles), each counted once: how a reader
// tells a second publisher from its own.
class WritersHeard {
 public:
  // Notes `writer`; returns how many distinct writers have been heard.
  std::uint32_t note(std::uint64_t writer) {
    if (std::find(writers_.begin(), writers_.end(), writer) == writers_.end())
      writers_.push_back(writer);
    return std::uint32_t(writers_.size());
  }

 private:
  std::vector<std::uint64_t> writers_;
};

// A station's writers carry "mixpilot.station=NAME" as USER_DATA; station_of() reads it back
// ("" when it is not such a tag).
std::string station_tag(const std::string& station);
std::string station_of(const void* user_data, std::size_t size);

// "rt/joy" from "joy", "/joy" or "rt/joy" (ROS 2's topic prefix rule).
std::string dds_topic(const std::string& ros_name);

// A DDS return code's text.
std::string dds_error(std::int32_t rc);

// System-clock nanoseconds (ROS time: the stamps of ROS 2 headers).
std::int64_t system_ns();

}  // namespace mixpilot::net
