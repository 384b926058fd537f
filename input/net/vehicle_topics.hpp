#pragma once
// The remote vehicle's topics and QoS (input/net/vehicle_msgs.idl), shared by its two sides.
// Internal to input/net: it includes Cyclone's headers.
#include <dds/dds.h>

namespace mixpilot::net {

inline constexpr const char* kVehicleCommandTopic = "rt/mixpilot/vehicle/command";
inline constexpr const char* kVehicleStateTopic = "rt/mixpilot/vehicle/state";

// Best effort, the newest `depth` samples: in a control loop a late sample is worth less than
// the next one, and a writer never waits for a reader.
inline dds_qos_t* best_effort_qos(int depth) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
  return qos;
}

}  // namespace mixpilot::net
