#pragma once
// Real-time priority (SPEC §4: the control thread runs under SCHED_FIFO where the system
// allows). The one place that asks for it: the control thread, the threads on its input path
// (a gamepad's poller, a network link's threads) just below it, so the controller never acts
// on input that waited behind other work. Where the system refuses, everything runs as before
// at normal priority.
namespace mixpilot {

// SCHED_FIFO priorities: modest (above every normal thread, below the kernel's own).
inline constexpr int kControlPriority = 10;  // the control loop
inline constexpr int kInputPriority = 9;     // a device poller feeding it

// The calling thread under SCHED_FIFO at `priority` (at most the system's maximum); false
// where the system refuses it.
bool ask_realtime_priority(int priority);

// While alive, the calling thread runs under SCHED_FIFO at the control priority (where the
// system allows), so the threads it starts inherit it: a control link's threads (Cyclone's
// receive threads, a reader) then wake as promptly as the control thread. The thread's own
// scheduling comes back after.
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

}  // namespace mixpilot
