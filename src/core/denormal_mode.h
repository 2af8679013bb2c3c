#pragma once
/// The CPU reference's treatment of denormals: kept (IEEE, the default), or flushed as a device that
/// can only flush them does (x86 MXCSR FTZ: a result below the smallest normal after rounding is
/// zero; DAZ: a denormal input reads as zero), so that both give the same bits.
#include <xmmintrin.h>

namespace tender {

/// Sets this thread's denormal mode while it lives (when `flush`), and restores the earlier mode.
class DenormalMode {
public:
  explicit DenormalMode(bool flush) : flush_(flush) {
    if (!flush_) return;
    saved_ = _mm_getcsr();
    _mm_setcsr(saved_ | kFlushToZero | kDenormalsAreZero);
  }
  ~DenormalMode() {
    if (flush_) _mm_setcsr(saved_);
  }
  DenormalMode(const DenormalMode&) = delete;
  DenormalMode& operator=(const DenormalMode&) = delete;

  static constexpr unsigned kFlushToZero = 0x8000u, kDenormalsAreZero = 0x0040u;

private:
  bool flush_;
  unsigned saved_ = 0;
};

} // namespace tender
