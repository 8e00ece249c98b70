// The render's signal handling; see interrupt.h. The handler only touches lock-free atomics
// and calls async-signal-safe functions (write, unlink, signal, raise).
#include "cli/interrupt.h"

#include <csignal>
#include <cstring>

#include <unistd.h>

#include "image/file_io.h"

namespace pt {
namespace {

std::atomic<bool> gStop{false};
std::atomic<int> gSignal{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free);

struct sigaction gPrevious[2];
bool gInstalled[2] = {false, false};
constexpr int kSignals[2] = {SIGINT, SIGTERM};

void say(const char* text) {
  // Nothing to do when stderr is gone; the stop goes ahead regardless.
  if (::write(STDERR_FILENO, text, std::strlen(text)) < 0) return;
}

void onSignal(int signal) {
  if (gStop.exchange(true)) {
    // The second signal: stop at once, leaving no temporary file behind.
    removeUnfinishedWrites();
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  gSignal.store(signal);
  say(signal == SIGINT
          ? "\npt: SIGINT: stopping after the work under way (Ctrl-C again stops at once)\n"
          : "\npt: SIGTERM: stopping after the work under way (a second one stops at once)\n");
}

}  // namespace

InterruptGuard::InterruptGuard() {
  gStop.store(false);
  gSignal.store(0);
  struct sigaction action {};
  action.sa_handler = onSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;  // file and device calls under way carry on
  for (int i = 0; i < 2; ++i) {
    // A signal the parent told us to ignore (SIGINT of a shell's background job) stays so.
    sigaction(kSignals[i], nullptr, &gPrevious[i]);
    gInstalled[i] = gPrevious[i].sa_handler != SIG_IGN;
    if (gInstalled[i]) sigaction(kSignals[i], &action, nullptr);
  }
}

InterruptGuard::~InterruptGuard() {
  for (int i = 0; i < 2; ++i) {
    if (gInstalled[i]) sigaction(kSignals[i], &gPrevious[i], nullptr);
  }
}

const std::atomic<bool>& InterruptGuard::stopFlag() const {
  return gStop;
}

const char* InterruptGuard::signalName() const {
  return gSignal.load() == SIGTERM ? "SIGTERM" : "SIGINT";
}

}  // namespace pt
