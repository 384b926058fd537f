#pragma once
// Real-time priority for the threads on a control loop's input path (SPEC §4: the control
// thread runs under SCHED_FIFO where the system allows): a network link's threads that wait
// behind other work make the controller act on old input. Where the system refuses,
// everything runs as before at normal priority.
#include <cstdint>

namespace mixpilot::input {

// While alive, the calling thread runs under SCHED_FIFO (where the system allows), so the
// threads it starts inherit it: a control link's threads (Cyclone's receive threads, a reader)
// then wake as promptly as the control thread. The thread's own scheduling comes back after.
class RealtimeThreadsScope {
 public:
  RealtimeThreadsScope();
  ~RealtimeThreadsScope();
  RealtimeThreadsScope(const RealtimeThreadsScope&) = delete;
  RealtimeThreadsScope& operator=(const RealtimeThreadsScope&) = delete;
  bool granted() const { return granted_; }

 private:
  int policy_ = 0;
  int priority_ = 0;
  bool granted_ = false;
};

}  // namespace mixpilot::input
