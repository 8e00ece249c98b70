// The BVH builders' thread team; see workers.h.
#include "bvh/workers.h"

#ifdef PT_BVH_PROFILE
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#endif

namespace pt {

Workers::Workers(int threads) {
  if (threads <= 0) threads = int(std::max(1u, std::thread::hardware_concurrency()));
  for (int w = 1; w < threads; ++w) threads_.emplace_back([this, w] { loop(w); });
}

Workers::~Workers() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void Workers::run(const std::function<void(int)>& task) {
  if (threads_.empty()) {
    task(0);
    return;
  }
  {
    std::lock_guard lock(mutex_);
    task_ = &task;
    pending_ = int(threads_.size());
    error_ = nullptr;
    ++generation_;
  }
  wake_.notify_all();
  std::exception_ptr mine;
  try {
    task(0);
  } catch (...) {
    mine = std::current_exception();
  }
  std::unique_lock lock(mutex_);
  done_.wait(lock, [this] { return pending_ == 0; });
  task_ = nullptr;
  if (mine) std::rethrow_exception(mine);
  if (error_) std::rethrow_exception(error_);
}

void Workers::loop(int worker) {
  unsigned long long seen = 0;
  for (;;) {
    const std::function<void(int)>* task;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      task = task_;
    }
    std::exception_ptr error;
    try {
      (*task)(worker);
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard lock(mutex_);
    if (error && !error_) error_ = error;
    if (--pending_ == 0) done_.notify_one();
  }
}

}  // namespace pt

#ifdef PT_BVH_PROFILE
namespace pt::build_profile {
namespace {

struct Mark {
  double wall, cpu, sys;
  long faults;
};

Mark now() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  auto seconds = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
  return Mark{
      std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(),
      seconds(usage.ru_utime) + seconds(usage.ru_stime), seconds(usage.ru_stime), usage.ru_minflt};
}

struct Phase {
  std::string name;
  Mark delta;
};
std::vector<Phase> phases;
Mark last = now();

}  // namespace

void begin() {
  phases.clear();
  last = now();
}

void phase(const std::string& name) {
  const Mark m = now();
  phases.push_back(Phase{
      name, Mark{m.wall - last.wall, m.cpu - last.cpu, m.sys - last.sys, m.faults - last.faults}});
  last = now();  // (the bookkeeping is not counted)
}

void end(const char* title) {
  phase("(rest)");
  Mark total{0, 0, 0, 0};
  std::fprintf(stderr, "%s\n%-34s %8s %6s %8s %8s %7s\n", title, "phase", "wall_ms", "share",
               "cpu_ms", "sys_ms", "faults");
  for (const Phase& p : phases) {
    total.wall += p.delta.wall, total.cpu += p.delta.cpu, total.sys += p.delta.sys;
    total.faults += p.delta.faults;
  }
  for (const Phase& p : phases) {
    std::fprintf(stderr, "%-34s %8.2f %5.1f%% %8.2f %8.2f %7ld\n", p.name.c_str(),
                 1e3 * p.delta.wall, 100 * p.delta.wall / total.wall, 1e3 * p.delta.cpu,
                 1e3 * p.delta.sys, p.delta.faults);
  }
  std::fprintf(stderr, "profile %s wall_ms=%.2f cpu_ms=%.2f sys_ms=%.2f faults=%ld\n", title,
               1e3 * total.wall, 1e3 * total.cpu, 1e3 * total.sys, total.faults);
  phases.clear();
  last = now();
}

}  // namespace pt::build_profile
#endif
