#include "worker_pool.h"

#include <chrono>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace tender {
namespace {

// How long an idle helper spins before it sleeps: longer than the serial gaps between the loops
// of a tick (waking a sleeper costs tens of microseconds), short enough to free the core soon
// after the last tick.
constexpr std::chrono::microseconds kSpinTime{1000};
// Spin iterations of the dispatcher waiting for the last chunks before it yields its core.
constexpr uint32_t kSpinIterations = 4096;

constexpr uint64_t kFieldMask = (1u << 20) - 1u;

inline void cpuRelax() {
#if defined(__SSE2__)
  _mm_pause();
#else
  std::this_thread::yield();
#endif
}

} // namespace

WorkerPool::WorkerPool(uint32_t threads) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  size_ = std::min(threads, 64u);
  helpers_.reserve(size_ - 1);
  // Helpers start from ticket 0, so a loop (or the stop) published before one runs is not missed.
  for (uint32_t i = 1; i < size_; ++i) helpers_.emplace_back([this] { helperLoop(0); });
}

WorkerPool::~WorkerPool() {
  stop_.store(true);
  ticket_.fetch_add(1);
  wakeHelpers();
  for (std::thread& t : helpers_) t.join();
}

// Wakes sleeping helpers; taking the mutex orders this after any helper's check of the ticket.
void WorkerPool::wakeHelpers() {
  { std::lock_guard<std::mutex> lock(sleep_mutex_); }
  wake_.notify_all();
}

// Claims and runs chunks of the current loop until none is left.
void WorkerPool::work() {
  uint64_t w = claim_.load();
  for (;;) {
    const uint64_t count = (w >> 20) & kFieldMask, next = w & kFieldMask;
    if (next >= count) return;
    if (claim_.compare_exchange_weak(w, w + 1)) {
      call_(job_, uint32_t(next));
      w = claim_.load();
    }
  }
}

void WorkerPool::dispatch(uint32_t chunks) {
  // Publish the loop (job_ and call_ are written before this store), then wake the helpers.
  ++job_id_;
  claim_.store(job_id_ << 40 | uint64_t(chunks) << 20);
  ticket_.fetch_add(1);
  if (sleepers_.load() > 0) wakeHelpers();
  work();
  // Every chunk is claimed; wait for helpers still running one. A helper that arrives later
  // finds nothing to claim and never touches this loop.
  for (uint32_t spin = 0; inflight_.load() != 0; ++spin)
    if (spin < kSpinIterations)
      cpuRelax();
    else
      std::this_thread::yield();
}

void WorkerPool::helperLoop(uint32_t seen) {
  for (;;) {
    uint32_t t = ticket_.load(std::memory_order_acquire);
    const auto spin_start = std::chrono::steady_clock::now();
    for (uint32_t spin = 1; t == seen; ++spin) {
      cpuRelax();
      t = ticket_.load(std::memory_order_acquire);
      if (spin % 64 == 0 && std::chrono::steady_clock::now() - spin_start > kSpinTime) break;
    }
    if (t == seen) {
      std::unique_lock<std::mutex> lock(sleep_mutex_);
      sleepers_.fetch_add(1); // seq_cst: either the dispatcher sees us or we see its ticket
      while ((t = ticket_.load()) == seen) wake_.wait(lock);
      sleepers_.fetch_sub(1);
    }
    seen = t;
    if (stop_.load()) return;
    inflight_.fetch_add(1); // seq_cst, before any claim: the dispatcher waits for us
    work();
    inflight_.fetch_sub(1);
  }
}

} // namespace tender
