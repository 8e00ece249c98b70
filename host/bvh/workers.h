// A fixed team of threads for the parallel phases of the BVH builders. The builders only
// give it work whose result cannot depend on how it is shared out (disjoint outputs, or exact
// combinations such as min, max and integer sums), so any thread count builds the same tree.
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

// Phase timers for profiling a build (docs/bvh-build.md): compiled only with -DPT_BVH_PROFILE,
// where PT_BVH_PHASE(name) ends the phase so named (wall time, the process's CPU time, which
// over the wall time says how parallel it ran, and its minor page faults since the previous
// mark; PT_BVH_PROFILE_BEGIN() starts the clock) and PT_BVH_PROFILE_END(title) prints the
// phases on stderr. Nothing in other builds.
#ifdef PT_BVH_PROFILE
#include <string>
namespace pt::build_profile {
void begin();
void phase(const std::string& name);
void end(const char* title);
}  // namespace pt::build_profile
#define PT_BVH_PROFILE_BEGIN() ::pt::build_profile::begin()
#define PT_BVH_PHASE(name) ::pt::build_profile::phase(name)
#define PT_BVH_PROFILE_END(title) ::pt::build_profile::end(title)
#else
#define PT_BVH_PROFILE_BEGIN() static_cast<void>(0)
#define PT_BVH_PHASE(name) static_cast<void>(0)
#define PT_BVH_PROFILE_END(title) static_cast<void>(0)
#endif

namespace pt {

class Workers {
 public:
  // `threads` workers, the calling thread being worker 0; 0 means one per hardware thread.
  explicit Workers(int threads);
  ~Workers();
  Workers(const Workers&) = delete;
  Workers& operator=(const Workers&) = delete;

  int count() const { return int(threads_.size()) + 1; }

  // Runs task(worker) once on every worker and returns when all have finished; rethrows
  // an exception thrown by a task (the caller's first).
  void run(const std::function<void(int)>& task);

  // Calls body(begin, end) on consecutive chunks of `grain` items covering [0, n), shared
  // out dynamically; on the calling thread alone when one chunk covers everything.
  template <typename Body>
  void forChunks(size_t n, size_t grain, const Body& body) {
    if (n == 0) return;
    grain = std::max<size_t>(grain, 1);
    if (n <= grain || count() == 1) {
      for (size_t b = 0; b < n; b += grain) body(b, std::min(n, b + grain));
      return;
    }
    std::atomic<size_t> next{0};
    run([&](int) {
      for (size_t b; (b = next.fetch_add(grain, std::memory_order_relaxed)) < n;) {
        body(b, std::min(n, b + grain));
      }
    });
  }

 private:
  void loop(int worker);

  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(int)>* task_ = nullptr;
  unsigned long long generation_ = 0;  // counts run() calls; a change wakes the workers
  int pending_ = 0;                    // workers other than the caller still running the task
  bool stop_ = false;
  std::exception_ptr error_;
};

}  // namespace pt
