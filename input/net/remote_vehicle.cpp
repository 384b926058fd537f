#include "input/net/remote_vehicle.hpp"

#include <dds/dds.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/modes/vehicle_feed.hpp"
#include "input/net/vehicle_topics.hpp"
#include "core/base/realtime_priority.hpp"

namespace mixpilot::net {

namespace {

constexpr int kTake = 16;

}  // namespace

bool RemoteVehicle::start(const Options& options, std::string& error) {
  options_ = options;
  if (options.nx < 1 || options.nx > VehicleSample::kMaxState) {
    error = "a vehicle state of " + std::to_string(options.nx) + " values is not supported";
    return false;
  }
  // A state that waits for a thread is predicted over the wrong horizon: the link's threads
  // (Cyclone's and the reader) run at the control thread's priority where allowed.
  const RealtimeThreadsScope realtime;
  if (!participant_.open(options.domain, error)) return false;
  VehicleTopics t;
  if (!open_vehicle_topics(participant_.handle(), false, kTake, t, error)) return false;
  reader_ = t.reader;
  writer_ = t.writer;
  waitset_ = t.waitset;
  sample_ = VehicleSample{};
  sample_.x.setZero(options.nx);
  sent_.reset();
  StateCheck::Limits limits;
  limits.nx = options.nx;
  limits.max_abs = options.max_abs;
  limits.max_delay_s = VehicleFeed::kMaxRtt;
  check_.setup(limits);
  running_ = true;
  thread_ = std::thread([this] { run(); });
  return true;
}

void RemoteVehicle::stop() {
  if (!running_.exchange(false)) return;
  if (waitset_ > 0) dds_waitset_set_trigger(waitset_, true);
  thread_.join();
  participant_.close();
}

bool RemoteVehicle::wait_for_vehicle(double seconds) const {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!heard() && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  return heard();
}

void RemoteVehicle::send(std::int64_t k, std::int64_t stamp_ns, const double* u, int nu) {
  sent_.note(k, stamp_ns);
  mixpilot_msgs_msg_dds__RotorCommand_ m{};
  m.step = k;
  m.stamp_ns = stamp_ns;
  m.end = false;
  m.u._length = m.u._maximum = std::uint32_t(nu);
  m.u._buffer = const_cast<double*>(u);
  dds_write(writer_, &m);
}

void RemoteVehicle::finish() {
  if (finished_.exchange(true) || writer_ <= 0) return;
  mixpilot_msgs_msg_dds__RotorCommand_ m{};
  m.step = sent_.sent();
  m.stamp_ns = vehicle_clock_ns();
  m.end = true;
  // Best effort: said three times, so one lost datagram does not leave the vehicle waiting.
  for (int i = 0; i < 3; ++i) dds_write(writer_, &m);
}

void RemoteVehicle::describe_rejection(char* text, std::size_t size) const {
  if (RejectionNote note; rejections_.last(note)) {
    describe(note, text, size);
  } else if (size > 0) {
    text[0] = '\0';
  }
}

void RemoteVehicle::run() {
  void* samples[kTake] = {};
  dds_sample_info_t infos[kTake];
  RejectionNote note;
  while (running_.load(std::memory_order_relaxed)) {
    dds_waitset_wait(waitset_, nullptr, 0, DDS_MSECS(20));
    const int n = dds_take(reader_, samples, infos, kTake, kTake);
    if (n <= 0) continue;
    bool changed = false;
    for (int i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const auto& m = *static_cast<const mixpilot_msgs_msg_dds__VehicleState_*>(samples[i]);
      const std::uint64_t writer = infos[i].publication_handle;
      publishers_.store(writers_.note(writer), std::memory_order_relaxed);
      if (vehicle_writer_ != 0 && writer != vehicle_writer_) {
        rejections_.add({Rejection::other_publisher,
                         "a state of a second vehicle (the first one heard flies)"});
        continue;
      }
      const std::int64_t received = vehicle_clock_ns();
      const StateFields fields{m.stamp_ns,      m.command_step, m.command_stamp_ns,
                               m.command_age_s, m.status,       m.x._length,
                               m.x._buffer};
      if (check_.check(fields, received, sent_, note) != Rejection::none) {
        rejections_.add(note);
        continue;
      }
      vehicle_writer_ = writer;
      std::copy_n(m.x._buffer, m.x._length, sample_.x.data());
      sample_.command = m.command_step;
      sample_.command_stamp_ns = m.command_step >= 0 ? m.command_stamp_ns : 0;
      sample_.command_age_s = m.command_age_s;
      sample_.left_world = m.status == 1;
      sample_.ended = m.status == 2;
      sample_.received_ns = received;
      ++sample_.serial;
      accepted_.fetch_add(1, std::memory_order_relaxed);
      changed = true;
    }
    dds_return_loan(reader_, samples, n);
    if (changed) {
      for_control_.publish(sample_);
      heard_.store(true, std::memory_order_release);
    }
  }
}

RemoteVehicleStats RemoteVehicle::stats() const {
  RemoteVehicleStats s;
  s.accepted = accepted_.load();
  s.bad_value = rejections_.count(Rejection::bad_value);
  s.bad_size = rejections_.count(Rejection::bad_size);
  s.unknown_command = rejections_.count(Rejection::unknown_command);
  s.stale = rejections_.count(Rejection::stale);
  s.other_publisher = rejections_.count(Rejection::other_publisher);
  s.publishers = publishers_.load();
  s.commands_sent = std::uint64_t(sent_.sent());
  char text[256];
  describe_rejection(text, sizeof text);
  s.last_rejection = text;
  return s;
}

}  // namespace mixpilot::net
