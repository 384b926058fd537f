#include "input/net/dds.hpp"

#include <dds/dds.h>

#include "core/scenario/data_files.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <regex>
#include <sstream>

namespace mixpilot::net {

namespace {

// The configuration text CYCLONEDDS_URI gives: inline XML, or the file(s) it names.
std::string config_text(const std::string& uri) {
  std::string text;
  std::stringstream parts(uri);
  std::string part;
  while (std::getline(parts, part, ',')) {
    const auto start = part.find_first_not_of(" \t");
    if (start == std::string::npos) continue;
    part = part.substr(start);
    if (!part.empty() && part.front() == '<') {
      text += part;
      continue;
    }
    if (part.starts_with("file://")) part = part.substr(7);
    std::ifstream in(part);
    std::stringstream ss;
    ss << in.rdbuf();
    text += ss.str();
  }
  return text;
}

}  // namespace

bool loopback_only(std::string& why) {
  const char* uri = std::getenv("CYCLONEDDS_URI");
  if (!uri || !*uri) {
    why = "CYCLONEDDS_URI is not set: Cyclone DDS would discover peers by multicast on every "
          "network interface (use " + loopback_config_uri() + ")";
    return false;
  }
  const std::string xml = config_text(uri);
  const auto has = [&](const char* re) { return std::regex_search(xml, std::regex(re)); };
  if (!has(R"re(<NetworkInterface[^>]*name\s*=\s*"lo")re") &&
      !has(R"re(<NetworkInterfaceAddress>\s*(lo|127\.0\.0\.1)\s*<)re")) {
    why = std::string("CYCLONEDDS_URI (") + uri + ") does not bind DDS to the loopback interface";
    return false;
  }
  if (!has(R"re(<AllowMulticast>\s*false\s*<)re")) {
    why = std::string("CYCLONEDDS_URI (") + uri + ") does not switch multicast off";
    return false;
  }
  if (!has(R"re(<Peer\s+address\s*=\s*"(127\.0\.0\.1|localhost)")re")) {
    why = std::string("CYCLONEDDS_URI (") + uri + ") names no peer 127.0.0.1";
    return false;
  }
  return true;
}

std::string loopback_config_uri() {
  const std::string path = data_file("assets/dds-loopback.xml");
  if (!path.empty() && std::filesystem::exists(path)) return "file://" + path;
  // Without the file, the same configuration inline.
  return "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/>"
         "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
         "<ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>40"
         "</MaxAutoParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers></Discovery>"
         "</Domain></CycloneDDS>";
}

void use_loopback_unless_configured() {
  if (const char* uri = std::getenv("CYCLONEDDS_URI"); !uri || !*uri)
    setenv("CYCLONEDDS_URI", loopback_config_uri().c_str(), 1);
}

// --- DDS Security ----------------------------------------------------------------------------

namespace {

std::mutex security_mutex;
std::optional<SecurityFiles> security_files_in_use;  // use_security()

// What the log sink gathered.
struct LogState {
  std::mutex mutex;
  std::uint64_t refused = 0;
  std::string last_refusal;
  std::string last_local_error;  // the newest security error about this process's own files
  bool said_refusal = false;
};
LogState& log_state() {
  static LogState s;
  return s;
}

std::string trimmed(const char* text, std::size_t size) {
  std::string t(text, size);
  while (!t.empty() && (t.back() == '\n' || t.back() == ' ')) t.pop_back();
  return t;
}

// Cyclone's log: security refusals of peers counted, this process's own security errors kept
// for the participant's error message, everything printed as Cyclone's default sink would
// (but only the first refusal: a refused peer retries every second).
void log_sink(void*, const dds_log_data_t* d) {
  if (!d || !d->message) return;
  // Cyclone's header ("<time> [<domain>] <thread>: ") precedes the message in its buffer.
  const std::string_view text(d->message, d->size);
  const auto has = [&](std::string_view part) { return text.find(part) != std::string_view::npos; };
  const bool refusal = (has("andshake") && (has("fail") || has("Fail"))) ||
                       has("Non secure remote") || has("security_attributes mismatch") ||
                       (has("remote") && (has("not allowed") || has("denied")));
  const bool local = has("validating local") || has("local identity") || has("local permission");
  LogState& s = log_state();
  bool print = true;
  {
    const std::lock_guard<std::mutex> lock(s.mutex);
    if (refusal) {
      ++s.refused;
      s.last_refusal = trimmed(text.data(), text.size());
      print = !s.said_refusal;
      s.said_refusal = true;
    } else if (local) {
      s.last_local_error = trimmed(text.data(), text.size());
    }
  }
  if (!print) return;
  std::fwrite(d->message - d->hdrsize, 1, d->hdrsize + d->size, stderr);
  std::fputc('\n', stderr);
  if (refusal)
    std::fputs("(mixpilot: further DDS Security refusals of peers are counted, not printed)\n",
               stderr);
}

// Where Debian keeps Cyclone's security plugins: beside libddsc, in libddsc0debian/.
std::string plugin(const char* name) {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&dds_create_participant), &info) && info.dli_fname) {
    const std::filesystem::path dir =
        std::filesystem::path(info.dli_fname).parent_path() / "libddsc0debian";
    const std::filesystem::path file = dir / ("lib" + std::string(name) + ".so");
    std::error_code ec;
    if (std::filesystem::exists(file, ec)) return file.string();
  }
  return name;  // Cyclone looks it up by its library name
}

}  // namespace

std::optional<SecurityFiles> security_files(const std::string& folder, std::string& error) {
  std::error_code ec;
  const std::filesystem::path dir = std::filesystem::absolute(folder, ec);
  if (ec || !std::filesystem::is_directory(dir, ec)) {
    error = "--dds-security " + folder + ": not a folder (it holds one identity's files, as "
            "mixpilot-security-ca makes a test set of them; docs/instructor-security.md)";
    return std::nullopt;
  }
  SecurityFiles f;
  f.folder = dir.lexically_normal().string();
  const std::pair<const char*, std::string*> files[] = {
      {"identity_ca.pem", &f.identity_ca},       {"cert.pem", &f.certificate},
      {"key.pem", &f.private_key},               {"permissions_ca.pem", &f.permissions_ca},
      {"governance.p7s", &f.governance},         {"permissions.p7s", &f.permissions}};
  for (const auto& [name, path] : files) {
    const std::filesystem::path p = dir / name;
    *path = p.lexically_normal().string();
    if (::access(path->c_str(), R_OK) != 0) {
      error = "--dds-security " + folder + ": " + name +
              (std::filesystem::exists(p, ec) ? " cannot be read" : " is missing") +
              " (the folder holds identity_ca.pem, cert.pem, key.pem, permissions_ca.pem, "
              "governance.p7s, permissions.p7s; docs/instructor-security.md)";
      return std::nullopt;
    }
  }
  return f;
}

void use_security(const SecurityFiles& files) {
  const std::lock_guard<std::mutex> lock(security_mutex);
  security_files_in_use = files;
}

const SecurityFiles* process_security() {
  const std::lock_guard<std::mutex> lock(security_mutex);
  return security_files_in_use ? &*security_files_in_use : nullptr;
}

bool security_in_config() {
  const char* uri = std::getenv("CYCLONEDDS_URI");
  if (!uri || !*uri) return false;
  return std::regex_search(config_text(uri), std::regex(R"(<(DDS)?Security[\s>])"));
}

SecurityLog security_log() {
  LogState& s = log_state();
  const std::lock_guard<std::mutex> lock(s.mutex);
  return {s.refused, s.last_refusal};
}

void install_log_sink() {
  static std::once_flag once;
  std::call_once(once, [] { dds_set_log_sink(&log_sink, nullptr); });
}

Participant::~Participant() { close(); }

bool Participant::open(std::uint32_t domain, std::string& error, const SecurityFiles* security) {
  close();
  install_log_sink();
  if (!security) security = process_security();
  dds_qos_t* qos = nullptr;
  if (security) {
    qos = dds_create_qos();
    const auto file = [](const std::string& p) { return "file:" + p; };
    const std::pair<const char*, std::string> props[] = {
        {"dds.sec.auth.library.path", plugin("dds_security_auth")},
        {"dds.sec.auth.library.init", "init_authentication"},
        {"dds.sec.auth.library.finalize", "finalize_authentication"},
        {"dds.sec.auth.identity_ca", file(security->identity_ca)},
        {"dds.sec.auth.identity_certificate", file(security->certificate)},
        {"dds.sec.auth.private_key", file(security->private_key)},
        {"dds.sec.crypto.library.path", plugin("dds_security_crypto")},
        {"dds.sec.crypto.library.init", "init_crypto"},
        {"dds.sec.crypto.library.finalize", "finalize_crypto"},
        {"dds.sec.access.library.path", plugin("dds_security_ac")},
        {"dds.sec.access.library.init", "init_access_control"},
        {"dds.sec.access.library.finalize", "finalize_access_control"},
        {"dds.sec.access.permissions_ca", file(security->permissions_ca)},
        {"dds.sec.access.governance", file(security->governance)},
        {"dds.sec.access.permissions", file(security->permissions)}};
    for (const auto& [name, value] : props) dds_qset_prop(qos, name, value.c_str());
  }
  {
    LogState& s = log_state();
    const std::lock_guard<std::mutex> lock(s.mutex);
    s.last_local_error.clear();
  }
  const dds_entity_t p = dds_create_participant(dds_domainid_t(domain), qos, nullptr);
  if (qos) dds_delete_qos(qos);
  if (p < 0) {
    std::string why;
    {
      LogState& s = log_state();
      const std::lock_guard<std::mutex> lock(s.mutex);
      why = s.last_local_error;
    }
    error = "DDS: cannot join domain " + std::to_string(domain) + " (" + dds_error(p);
    if (security) error += "; DDS Security with " + security->folder;
    if (!why.empty()) error += ": " + why;
    error += security ? ")" : "; check CYCLONEDDS_URI)";
    return false;
  }
  handle_ = p;
  domain_ = domain;
  return true;
}

void Participant::close() {
  if (handle_ > 0) dds_delete(handle_);
  handle_ = 0;
}

namespace {
constexpr std::string_view kStationTag = "mixpilot.station=";
}

std::string station_tag(const std::string& station) { return std::string(kStationTag) + station; }

std::string station_of(const void* user_data, std::size_t size) {
  if (!user_data) return {};
  const std::string_view s(static_cast<const char*>(user_data), size);
  if (!s.starts_with(kStationTag)) return {};
  return std::string(s.substr(kStationTag.size()));
}

std::string dds_topic(const std::string& ros_name) {
  if (ros_name.starts_with("rt/")) return ros_name;
  if (ros_name.starts_with("/")) return "rt" + ros_name;
  return "rt/" + ros_name;
}

std::string dds_error(std::int32_t rc) { return dds_strretcode(rc); }

std::int64_t system_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace mixpilot::net
