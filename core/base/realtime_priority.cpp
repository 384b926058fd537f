#include "core/base/realtime_priority.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>

namespace mixpilot {

bool ask_realtime_priority(int priority) {
  sched_param p{};
  p.sched_priority = std::min(priority, sched_get_priority_max(SCHED_FIFO));
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
}

RealtimeThreadsScope::RealtimeThreadsScope() {
  sched_param old{};
  if (pthread_getschedparam(pthread_self(), &policy_, &old) != 0) return;
  priority_ = old.sched_priority;
  granted_ = ask_realtime_priority(kControlPriority);
}

RealtimeThreadsScope::~RealtimeThreadsScope() {
  if (!granted_) return;
  sched_param old{};
  old.sched_priority = priority_;
  pthread_setschedparam(pthread_self(), policy_, &old);
}

}  // namespace mixpilot
