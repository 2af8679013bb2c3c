#pragma once
/// A small persistent pool of worker threads that runs one parallel loop at a time.
/// A loop is cut into chunks that the workers claim one by one (the calling thread takes part),
/// so a helper the OS has not scheduled yet never holds up the loop: the others take its share.
/// Helpers spin briefly between loops, then sleep on a condition variable.
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
  explicit WorkerPool(uint32_t threads);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  /// Number of workers, the caller included.
  uint32_t size() const { return size_; }

  /// Calls f(chunk) for every chunk in [0, chunks), spread over the workers, and returns when
  /// every call has returned. With one chunk (or one worker) f runs on the caller alone.
  template <typename F>
  void run(uint32_t chunks, F&& f) {
    if (chunks <= 1 || size_ == 1) {
      for (uint32_t c = 0; c < chunks; ++c) f(c);
      return;
    }
    using Fn = std::remove_reference_t<F>;
    job_ = const_cast<void*>(static_cast<const void*>(&f));
    call_ = [](void* ctx, uint32_t c) { (*static_cast<Fn*>(ctx))(c); };
    dispatch(chunks);
  }

  /// Splits [0, n) into contiguous ranges of at least `grain` elements (kChunksPerWorker per worker) and
  /// calls f(begin, end) for each; small loops run on the caller alone. Range bounds are
  /// multiples of 4, so SIMD loops see whole groups.
  template <typename F>
  void parallelFor(uint32_t n, uint32_t grain, F&& f) {
    const uint32_t chunks = std::min<uint32_t>(size_ * kChunksPerWorker, n / std::max(grain, 1u));
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

  /// Chunks per worker in parallelFor. One contiguous share each keeps a thread on the same
  /// particles from colour to colour (measured fastest: fewer cache lines move between cores);
  /// a share no helper has claimed yet is still taken by whichever worker is free.
  static constexpr uint32_t kChunksPerWorker = 1;

private:
  void dispatch(uint32_t chunks);
  void work();
  void wakeHelpers();
  void helperLoop(uint32_t seen);

  uint32_t size_ = 1;
  std::vector<std::thread> helpers_;
  void* job_ = nullptr;
  void (*call_)(void*, uint32_t) = nullptr;
  uint64_t job_id_ = 0;
  // The current loop in one word: job id << 40 | chunk count << 20 | next unclaimed chunk.
  std::atomic<uint64_t> claim_{0};
  std::atomic<uint32_t> inflight_{0}; // helpers inside work()
  std::atomic<uint32_t> ticket_{0};   // bumped once per loop to wake the helpers
  std::atomic<uint32_t> sleepers_{0}; // helpers asleep on wake_
  std::mutex sleep_mutex_;
  std::condition_variable wake_;
  std::atomic<bool> stop_{false};
};

} // namespace tender
