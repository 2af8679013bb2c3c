#include "worker_pool.h"

#include <chrono>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "core/denormal_mode.h"

namespace tender {
namespace {

// How long an idle helper spins before it sleeps: about what waking a sleeper costs, so a helper
// catches the next job of a run of short ones at once, and sleeps through the serial stretches of
// a tick (contact's list builds and sorts) instead of burning its core there. At 1 ms it spun
// through them: the hand's crumple took as long (4.5 s for 75 ticks) and 20 % more CPU time.
constexpr std::chrono::microseconds kSpinTime{50};
// Spin iterations of a worker waiting inside a job (for a phase, or for the last chunks) before
// it yields its core, so a worker the OS has descheduled gets it back on an oversubscribed machine.
constexpr uint32_t kSpinIterations = 4096;

// Fields of the claim word.
constexpr uint32_t kPhaseShift = 32, kJobShift = 44;
constexpr uint64_t kPhaseMask = (uint64_t(1) << (kJobShift - kPhaseShift)) - 1u;
constexpr uint64_t kJobMask = (uint64_t(1) << (64 - kJobShift)) - 1u;
constexpr uint64_t kChunkMask = (uint64_t(1) << kPhaseShift) - 1u;
static_assert(WorkerPool::kMaxChunks <= kPhaseShift && WorkerPool::kMaxPhases <= kPhaseMask + 1);

inline void cpuRelax() {
#if defined(__SSE2__)
  _mm_pause();
#else
  std::this_thread::yield();
#endif
}

// Spins until done() holds, yielding the core after a while.
template <typename Done>
void waitUntil(Done done) {
  for (uint32_t spin = 0; !done(); ++spin)
    if (spin < kSpinIterations)
      cpuRelax();
    else
      std::this_thread::yield();
}

} // namespace

WorkerPool::WorkerPool(uint32_t threads, bool flush_denormals) : flush_denormals_(flush_denormals) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  size_ = std::min(threads, 64u);
  helpers_.reserve(size_ - 1);
  // Helpers start from ticket 0, so a job (or the stop) published before one runs is not missed.
  for (uint32_t i = 1; i < size_; ++i) helpers_.emplace_back([this, i] { helperLoop(i); });
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

// Claims and runs chunks of the current job until every chunk of its last phase is claimed.
void WorkerPool::work(uint32_t worker) {
  uint64_t w = claim_.load(std::memory_order_acquire);
  for (;;) {
    if ((w >> kJobShift) == 0) return; // closed: no job, or the next one is being published
    // Read after the word: at least as new as its job (see claim_).
    const uint32_t phases = phases_.load(std::memory_order_acquire), chunks = chunks_.load(std::memory_order_acquire);
    const uint64_t all = (uint64_t(1) << chunks) - 1u;
    uint32_t phase = uint32_t((w >> kPhaseShift) & kPhaseMask);
    uint64_t claimed = w & kChunkMask;
    if (phase >= phases) return; // no job yet
    if ((claimed & all) == all) {
      if (phase + 1 >= phases) return; // every chunk of the job is claimed
      ++phase;
      claimed = 0;
    }
    // This worker's own chunk if it is free, else the next free one after it (cyclically).
    const uint64_t free = ~claimed & all, after = free & (~uint64_t(0) << (worker % chunks));
    const uint32_t chunk = uint32_t(__builtin_ctzll(after ? after : free));
    const uint64_t desired =
        (w & (kJobMask << kJobShift)) | uint64_t(phase) << kPhaseShift | claimed | uint64_t(1) << chunk;
    if (!claim_.compare_exchange_weak(w, desired, std::memory_order_acq_rel, std::memory_order_acquire)) continue;
    // Every chunk of the earlier phases is claimed; wait until they have all returned.
    const uint32_t before = phase * chunks;
    waitUntil([&] { return done_.load(std::memory_order_acquire) >= before; });
    call_.load(std::memory_order_relaxed)(ctx_.load(std::memory_order_relaxed), phase, chunk);
    done_.fetch_add(1, std::memory_order_acq_rel);
    w = claim_.load(std::memory_order_acquire);
  }
}

void WorkerPool::dispatch(void* ctx, Call call, uint32_t phases, uint32_t chunks) {
  // Close the finished job before its fields change: a worker still holding its claim word would
  // read that word with the new job's counts and could claim a chunk in it. Once a worker sees a
  // new field (release/acquire), its compare-exchange sees the closed word (or a newer one) and fails.
  claim_.store(0, std::memory_order_release);
  // Publish the job (its fields before the claim word), then wake the helpers.
  ctx_.store(ctx, std::memory_order_release);
  call_.store(call, std::memory_order_release);
  phases_.store(phases, std::memory_order_release);
  chunks_.store(chunks, std::memory_order_release);
  done_.store(0, std::memory_order_release);
  job_id_ = job_id_ % kJobMask + 1; // 1, 2, ..., kJobMask: job id 0 is the closed word
  claim_.store(job_id_ << kJobShift, std::memory_order_release);
  ticket_.fetch_add(1);
  if (sleepers_.load() > 0) wakeHelpers();
  {
    const DenormalMode mode(flush_denormals_);
    work(0);
  }
  // Every chunk is claimed; wait for those still running. Only a helper that claimed a chunk can
  // hold this up: one that arrives later finds nothing to claim and never touches this job.
  const uint32_t total = phases * chunks;
  waitUntil([&] { return done_.load(std::memory_order_acquire) == total; });
}

void WorkerPool::helperLoop(uint32_t worker) {
  const DenormalMode mode(flush_denormals_); // for the thread's whole life: it runs only jobs
  uint32_t seen = 0;
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
    work(worker);
  }
}

} // namespace tender
