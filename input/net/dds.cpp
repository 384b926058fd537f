#include "input/net/dds.hpp"

#include <dds/dds.h>

#include "core/scenario/data_files.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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

Participant::~Participant() { close(); }

bool Participant::open(std::uint32_t domain, std::string& error) {
  close();
  const dds_entity_t p = dds_create_participant(dds_domainid_t(domain), nullptr, nullptr);
  if (p < 0) {
    error = "DDS: cannot join domain " + std::to_string(domain) + " (" + dds_error(p) +
            "; check CYCLONEDDS_URI)";
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
