// SIGINT and SIGTERM during a render: the first asks the render to stop after the work under
// way (the command line then writes what is complete); a second ends the process at once.
#pragma once

#include <atomic>

namespace pt {

// While one exists, SIGINT and SIGTERM are caught: the first sets stopFlag() and says on
// stderr that the render is stopping; a second removes the temporary files of writes under
// way and ends the process by that signal, as if it had not been caught. The previous
// handlers come back when it is destroyed.
class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

  const std::atomic<bool>& stopFlag() const;
  bool interrupted() const { return stopFlag().load(); }
  const char* signalName() const;  // "SIGINT" or "SIGTERM" once interrupted
};

}  // namespace pt
