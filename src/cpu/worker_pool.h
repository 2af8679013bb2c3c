#pragma once
/// A small persistent pool of worker threads that runs one parallel job at a time.
/// A job is a sequence of phases, each cut into chunks; a phase starts once every chunk of the
/// previous one has returned (a barrier without a fork/join). The workers claim chunks one by
/// one (the calling thread takes part), each preferring the chunk of its own number, so a worker
/// stays on the same data from phase to phase, while a chunk no one has claimed yet is taken by
/// whichever worker is free: a helper the OS has not scheduled never holds up a job unless it
/// is running one of its chunks. Helpers spin briefly between jobs, then sleep on a condition
/// variable; waits inside a job spin briefly, then yield the core.
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace tender {

class WorkerPool {
public:
  /// Starts `threads - 1` helper threads; 0 means one worker per hardware thread (at most 64).
  /// With `flush_denormals` every job runs with denormals flushed (DenormalMode) on every worker.
  explicit WorkerPool(uint32_t threads, bool flush_denormals = false);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  /// Number of workers, the caller included.
  uint32_t size() const { return size_; }

  /// Most chunks in one phase, and most phases in one job.
  static constexpr uint32_t kMaxChunks = 32, kMaxPhases = 4096;

  /// Calls f(phase, chunk) for every phase in [0, phases) and chunk in [0, chunks) (chunks is
  /// clamped to kMaxChunks; phases must not exceed kMaxPhases). The calls of a phase start once
  /// every call of the previous phase has returned, and their writes are visible to them. Returns
  /// when every call has returned. With one chunk (or one worker) f runs on the caller alone.
  template <typename F>
  void runPhases(uint32_t phases, uint32_t chunks, F&& f) {
    chunks = std::min(chunks, kMaxChunks);
    if (phases == 0 || chunks == 0) return;
    if (chunks == 1 || size_ == 1) {
      for (uint32_t p = 0; p < phases; ++p)
        for (uint32_t c = 0; c < chunks; ++c) f(p, c);
      return;
    }
    using Fn = std::remove_reference_t<F>;
    dispatch(
        const_cast<void*>(static_cast<const void*>(&f)),
        [](void* ctx, uint32_t p, uint32_t c) { (*static_cast<Fn*>(ctx))(p, c); }, phases, chunks);
  }

  /// Calls f(chunk) for every chunk in [0, chunks) (at most kMaxChunks), spread over the workers.
  template <typename F>
  void run(uint32_t chunks, F&& f) {
    runPhases(1, chunks, [&](uint32_t, uint32_t c) { f(c); });
  }

  /// Number of chunks parallelFor cuts [0, n) into: `per_worker` per worker, at least `grain`
  /// elements each, at most kMaxChunks; 1 means the caller runs the loop alone.
  uint32_t chunksFor(uint32_t n, uint32_t grain, uint32_t per_worker = 1) const {
    return std::max(1u, std::min({size_ * per_worker, n / std::max(grain, 1u), kMaxChunks}));
  }

  /// Splits [0, n) into chunksFor(n, grain, per_worker) contiguous ranges and calls f(begin, end)
  /// for each; small loops run on the caller alone. Range bounds are multiples of 4, so SIMD
  /// loops see whole groups. One share per worker (the default) keeps a thread on the same
  /// elements from loop to loop; more shares balance loops whose elements differ in cost.
  template <typename F>
  void parallelFor(uint32_t n, uint32_t grain, F&& f, uint32_t per_worker = 1) {
    const uint32_t chunks = chunksFor(n, grain, per_worker);
    if (chunks <= 1 || size_ == 1) {
      if (n > 0) f(0u, n);
      return;
    }
    run(chunks, [&](uint32_t c) {
      const uint32_t begin = chunkBound(n, chunks, c), end = chunkBound(n, chunks, c + 1);
      if (begin < end) f(begin, end);
    });
  }

  /// Start of chunk c of [0, n) cut into `parts` (a multiple of 4, except the end n).
  static uint32_t chunkBound(uint32_t n, uint32_t parts, uint32_t c) {
    if (c >= parts) return n;
    return uint32_t((uint64_t(n) * c / parts) & ~uint64_t(3));
  }

private:
  using Call = void (*)(void*, uint32_t, uint32_t);
  void dispatch(void* ctx, Call call, uint32_t phases, uint32_t chunks);
  void work(uint32_t worker);
  void wakeHelpers();
  void helperLoop(uint32_t worker);

  uint32_t size_ = 1;
  bool flush_denormals_ = false;
  std::vector<std::thread> helpers_;
  uint64_t job_id_ = 0;
  // The current job in one word: job id << 44 | phase << 32 | bit mask of its claimed chunks;
  // job id 0 means no job (the word is closed while the next job's fields are written).
  // A claim is a compare-exchange of this word, so a worker holding a stale copy (an earlier job)
  // never claims anything; the fields below are read after loading it, and a claim that succeeds
  // proves they belong to its job (they are rewritten only once every chunk has returned).
  std::atomic<uint64_t> claim_{0};
  std::atomic<void*> ctx_{nullptr};
  std::atomic<Call> call_{nullptr};
  std::atomic<uint32_t> phases_{0}, chunks_{1};
  std::atomic<uint32_t> done_{0};     // chunks of the current job that have returned
  std::atomic<uint32_t> ticket_{0};   // bumped once per job to wake the helpers
  std::atomic<uint32_t> sleepers_{0}; // helpers asleep on wake_
  std::mutex sleep_mutex_;
  std::condition_variable wake_;
  std::atomic<bool> stop_{false};
};

} // namespace tender
