#pragma once
/// The CPU reference as a SheetBatch: one single-threaded CpuSolver per sheet, the sheets of a
/// batch spread over a pool of worker threads (each sheet's tick runs whole on one worker, so a
/// small sheet, which one thread runs best, keeps every core busy).
#include <memory>
#include <vector>

#include "core/fleet.h"
#include "cpu/cpu_solver.h"
#include "cpu/worker_pool.h"

namespace tender {

class CpuBatch final : public SheetBatch {
public:
  /// `sheets` solvers with these options per sheet (their thread count is ignored: one each) on
  /// `threads` workers (0: one per hardware thread).
  CpuBatch(uint32_t sheets, uint32_t threads, CpuOptions per_sheet = {});
  ~CpuBatch() override;

  std::string name() const override { return "cpu"; }
  uint32_t size() const override { return uint32_t(queued_.size()); }
  Solver& sheet(uint32_t i) override { return *queued_[i]; }
  void flush() override;
  void finish() override {}
  uint64_t memoryBytes() const override;
  uint32_t dispatchesPerFlush() const override { return last_jobs_; }
  /// Worker threads, the caller included.
  uint32_t threads() const { return pool_.size(); }

private:
  WorkerPool pool_;
  std::vector<std::unique_ptr<CpuSolver>> solvers_;
  std::vector<std::unique_ptr<QueuedSolver>> queued_;
  std::vector<uint32_t> jobs_; ///< sheets with a queued tick, in the flush running
  uint32_t last_jobs_ = 0;
};

} // namespace tender
