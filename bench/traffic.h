#pragma once
/// tender-bench's memory-traffic model and peak-bandwidth measurements.
///
/// The model counts the bytes each pass of a tick must read and write at least, given the data
/// layout of the solver that runs it: every array element a pass touches counts once per pass
/// (per dispatch on the GPU), whole records (a position is 16 bytes even where only xyz is used),
/// and nothing is assumed to stay in a cache from one pass to the next. Achieved bandwidth is that
/// count over the measured time; the peak is measured on the same machine by copying a large
/// buffer, so "percent of peak" says how close a pass comes to streaming memory.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/sheet.h"

namespace tender::bench {

/// The data layout whose traffic is counted.
enum class Layout {
  Cpu,      ///< CpuSolver: split constraint arrays, SoA positions in hash order
  Gpu,      ///< GpuSolver, the per-colour passes
  GpuFused, ///< GpuSolver, integration and projection in one workgroup (positions in shared memory)
};

/// Minimum bytes one pass reads and writes in one tick (all substeps).
struct PassTraffic {
  std::string name; ///< as in Solver::passTimes(): integrate, project, hash, collide, floor, tear
  uint64_t read = 0, write = 0;
  uint64_t bytes() const { return read + write; }
};

/// The bytes every pass of one tick with these uniforms must move (see traffic.cpp, one comment
/// per pass). Counts come from the topology (particles, constraints per colour, hash buckets,
/// adjacency) and record sizes from the types the solvers store. Steady state: the tear
/// compaction, which runs only in a substep where something tore, and the once-per-frame normals
/// pass are not part of it; with `candidate_lists`, the collision candidate lists are in use (no
/// hash is built).
std::vector<PassTraffic> tickTraffic(const SheetTopology& topo, const shaderio::SimUniforms& u, Layout layout,
                                     bool candidate_lists = false);

/// A measured copy bandwidth.
struct PeakBandwidth {
  double gbps = 0.0;         ///< best of the repetitions, (read + write bytes) / s / 1e9
  uint64_t buffer_bytes = 0; ///< size of the copied buffer (the source; the destination is as big)
  uint32_t repetitions = 0;  ///< timed copies
  uint32_t threads = 0;      ///< host copy: threads used (0 on a device)
  std::string method;        ///< how it was measured, in words
};

/// memcpy of a large buffer split over `threads` workers (0 = one per hardware thread, as the CPU
/// solver's `threads` parameter), best of several repetitions after one that touches the pages.
PeakBandwidth measureHostCopy(uint32_t threads);

#ifdef TENDER_HAS_GPU
/// vkCmdCopyBuffer of a large device-local buffer on device `device` (-1: the solver's default
/// choice), timed with timestamp queries, best of several; nullopt and a one-line `error` when
/// the device cannot be opened, has no timestamps, or cannot hold the buffers.
std::optional<PeakBandwidth> measureDeviceCopy(int device, std::string& error);
#endif

} // namespace tender::bench
