// What the command line reports on stderr while and after rendering: progress for long
// renders (a live bar on a terminal, a line every few seconds otherwise; silent for work that
// finishes within a second) and the one message for samples left out of an image.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

#include <unistd.h>

namespace pt {

class Progress {
 public:
  explicit Progress(std::string label)
      : label_(std::move(label)), start_(Clock::now()), last_(start_), tty_(isatty(2) != 0) {}

  // fraction in [0, 1]; cheap to call often.
  void update(double fraction) {
    const auto now = Clock::now();
    const double elapsed = seconds(now - start_);
    if (elapsed < 1.0) return;
    const double sinceLast = seconds(now - last_);
    if (sinceLast < (tty_ ? 0.1 : 5.0) && fraction < 1.0) return;
    if (!tty_ && fraction >= 1.0 && printedFinal_) return;
    last_ = now;
    const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
    if (tty_) {
      constexpr int kWidth = 30;
      const int filled = int(fraction * kWidth + 0.5);
      std::fprintf(stderr, "\r%s [%s%s] %5.1f%%  %.0fs elapsed, %.0fs left ", label_.c_str(),
                   std::string(size_t(filled), '#').c_str(),
                   std::string(size_t(kWidth - filled), '.').c_str(), 100.0 * fraction, elapsed,
                   eta);
      shown_ = true;
    } else {
      std::fprintf(stderr, "%s: %.1f%% after %.0fs, about %.0fs left\n", label_.c_str(),
                   100.0 * fraction, elapsed, eta);
      printedFinal_ = fraction >= 1.0;
    }
    std::fflush(stderr);
  }

  // Ends the live bar's line so the next output starts on a fresh line.
  void finish() {
    if (tty_ && shown_) std::fputc('\n', stderr);
    shown_ = false;
  }

 private:
  using Clock = std::chrono::steady_clock;
  static double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }
  std::string label_;
  Clock::time_point start_, last_;
  bool tty_;
  bool shown_ = false;
  bool printedFinal_ = false;
};

// Samples that were NaN/Inf or cut short (`truncated` of them) are never added to the image;
// the command then exits with kExitFailure.
inline void printInvalidSamples(uint64_t invalid, uint64_t truncated) {
  std::fprintf(stderr, "error: %llu samples were NaN or Inf%s; they were left out of the image\n",
               (unsigned long long)invalid,
               truncated > 0 ? " or cut short by lavapipe's loop-iteration cap" : "");
}

}  // namespace pt
