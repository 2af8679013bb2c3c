#include "cpu_batch.h"

#include <atomic>

namespace tender {

CpuBatch::CpuBatch(uint32_t sheets, uint32_t threads, CpuOptions per_sheet) : pool_(threads) {
  per_sheet.threads = 1;
  solvers_.reserve(sheets);
  queued_.reserve(sheets);
  for (uint32_t i = 0; i < sheets; ++i) {
    solvers_.push_back(std::make_unique<CpuSolver>(per_sheet));
    queued_.push_back(std::make_unique<QueuedSolver>(*this, *solvers_.back()));
  }
}

CpuBatch::~CpuBatch() = default;

void CpuBatch::flush() {
  jobs_.clear();
  for (uint32_t i = 0; i < queued_.size(); ++i)
    if (queued_[i]->queued()) jobs_.push_back(i);
  if (jobs_.empty()) return;
  last_jobs_ = uint32_t(jobs_.size());
  // Each worker takes the next sheet until none is left: a sheet's tick is whole on one thread
  // (the same arithmetic, in the same order, as the sheet run alone).
  std::atomic<uint32_t> next{0};
  const uint32_t workers = std::min<uint32_t>(pool_.size(), uint32_t(jobs_.size()));
  pool_.run(workers, [&](uint32_t) {
    for (uint32_t k = next.fetch_add(1); k < jobs_.size(); k = next.fetch_add(1)) {
      QueuedSolver& q = *queued_[jobs_[k]];
      q.inner().tick(*q.queued());
    }
  });
  for (uint32_t i : jobs_) queued_[i]->queued().reset();
}

uint64_t CpuBatch::memoryBytes() const {
  uint64_t total = 0;
  for (const auto& s : solvers_) total += s->memoryBytes();
  return total;
}

} // namespace tender
