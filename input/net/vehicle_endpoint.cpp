#include "input/net/vehicle_endpoint.hpp"

#include <algorithm>
#include <cmath>

#include "core/modes/vehicle_link.hpp"
#include "input/net/vehicle_topics.hpp"

namespace mixpilot::net {

namespace {
constexpr int kTake = 32;
}  // namespace

bool VehicleEndpoint::open(std::uint32_t domain, const CommandCheck::Limits& limits,
                           std::string& error) {
  const int nu = limits.nu;
  if (nu < 1 || nu > VehicleCommand::kMaxInputs) {
    error = "a vehicle of " + std::to_string(nu) + " inputs is not supported";
    return false;
  }
  if (!(limits.dt > 0.0) || !(limits.u_max > limits.u_min)) {
    error = "a vehicle needs a positive control period and rotor limits";
    return false;
  }
  nu_ = nu;
  check_.setup(limits);
  // Cyclone's threads inherit the vehicle loop's real-time priority (app/vehicle.cpp).
  if (!participant_.open(domain, error)) return false;
  VehicleTopics t;
  if (!open_vehicle_topics(participant_.handle(), true, kTake, t, error)) return false;
  reader_ = t.reader;
  writer_ = t.writer;
  waitset_ = t.waitset;
  return true;
}

void VehicleEndpoint::wait(std::int64_t timeout_ns, std::vector<VehicleCommand>& out) {
  if (timeout_ns > 0) dds_waitset_wait(waitset_, nullptr, 0, timeout_ns);
  void* samples[kTake] = {};
  dds_sample_info_t infos[kTake];
  RejectionNote note;
  const int n = dds_take(reader_, samples, infos, kTake, kTake);
  for (int i = 0; i < n; ++i) {
    if (!infos[i].valid_data) continue;
    const auto& m = *static_cast<const mixpilot_msgs_msg_dds__RotorCommand_*>(samples[i]);
    const std::uint64_t writer = infos[i].publication_handle;
    stats_.publishers = writers_.note(writer);
    if (controller_ != 0 && writer != controller_) {
      rejections_.add({Rejection::other_publisher,
                       "a command of a second controller (the first one heard flies)"});
      continue;
    }
    if (m.end) {
      if (controller_ == 0) continue;  // nothing flown: not this vehicle's flight
      out.push_back(VehicleCommand{m.step, m.stamp_ns, true, {}});
      continue;
    }
    const CommandFields fields{m.step, m.stamp_ns, m.u._length, m.u._buffer};
    if (check_.check(fields, vehicle_clock_ns(), note) != Rejection::none) {
      rejections_.add(note);
      continue;
    }
    controller_ = writer;
    ++stats_.accepted;
    VehicleCommand c{m.step, m.stamp_ns, false, {}};
    std::copy_n(m.u._buffer, nu_, c.u.begin());
    out.push_back(c);
  }
  if (n > 0) dds_return_loan(reader_, samples, n);
}

void VehicleEndpoint::publish(const VehicleStateOut& s) {
  mixpilot_msgs_msg_dds__VehicleState_ m{};
  m.stamp_ns = s.stamp_ns;
  m.command_step = s.command_step;
  m.command_stamp_ns = s.command_stamp_ns;
  m.command_age_s = s.command_age_s;
  m.status = s.status;
  m.x._length = m.x._maximum = std::uint32_t(s.nx);
  m.x._buffer = const_cast<double*>(s.x);
  if (dds_write(writer_, &m) >= 0) ++stats_.states_sent;
}

VehicleEndpointStats VehicleEndpoint::stats() const {
  VehicleEndpointStats s = stats_;
  s.bad_value = rejections_.count(Rejection::bad_value);
  s.bad_size = rejections_.count(Rejection::bad_size);
  s.stale = rejections_.count(Rejection::stale);
  s.other_publisher = rejections_.count(Rejection::other_publisher);
  if (RejectionNote note; rejections_.last(note)) {
    char text[256];
    describe(note, text, sizeof text);
    s.last_rejection = text;
  }
  return s;
}

std::uint32_t VehicleEndpoint::controllers() const {
  dds_subscription_matched_status_t st{};
  if (dds_get_subscription_matched_status(reader_, &st) < 0) return 0;
  return st.current_count;
}

}  // namespace mixpilot::net
