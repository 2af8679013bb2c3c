#pragma once
/// The cases of tender-bench: its options, the sizes, one size on one backend (runCase) and a
/// fleet of sheets of one size (runBatchCase), each as a JSON record.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "traffic.h"

namespace tender::bench {

/// Command-line options.
struct BenchOptions {
  std::string sizes = "32x48,64x96,128x192,256x384,512x768,1024x1536,2048x3072";
  std::string backends;
  std::string preset = "tender";
  std::vector<std::string> sets;
  uint32_t ticks = 60;
  uint32_t warmup = 10;
  int device = -1;
  uint32_t fused_workgroup = 0; ///< the GPU's fused tick's workgroup (BackendOptions); 0 = the device kind's
  std::string json, csv;
  uint64_t max_cpu_particles = 400000;
  double max_seconds = 30.0;
  bool no_peak = false;          ///< skip the copy-bandwidth measurement of the host and the device
  std::vector<uint32_t> batches; ///< --batch: fleets of these many sheets per size and backend
};

/// Measured copy bandwidths that results are compared with (absent: not measured).
struct Peaks {
  std::optional<PeakBandwidth> cpu, gpu;
};

/// One grid size.
struct Size {
  uint32_t cols = 0, rows = 0;
  std::string text() const { return std::to_string(cols) + "x" + std::to_string(rows); }
};

/// Progress on stderr: one line rewritten in place on a terminal, a line per case otherwise.
class Progress {
public:
  Progress() : tty_(isatty(STDERR_FILENO) != 0) {}
  void update(const std::string& text, bool final_line) {
    if (tty_) {
      std::fprintf(stderr, "\r%-100s%s", text.c_str(), final_line ? "\n" : "");
    } else if (final_line) {
      std::fprintf(stderr, "%s\n", text.c_str());
    }
    std::fflush(stderr);
  }
  bool live() const { return tty_; }

private:
  bool tty_;
};

/// The parts of `s` between separators `sep` (an empty string has none).
std::vector<std::string> split(const std::string& s, char sep);
/// Parses --sizes: WxH, comma-separated.
std::optional<std::string> parseSizes(const std::string& text, std::vector<Size>& out);
/// The CPU's model name (/proc/cpuinfo), or "unknown".
std::string cpuModel();
/// Runs one size on one backend and returns its JSON record (or the record of why it was skipped).
nlohmann::json runCase(const BenchOptions& o, const Peaks& peaks, const Size& size, const std::string& backend,
                       const std::string& label, Progress& progress);
/// Runs a fleet of `sheets` sheets of one size on one backend and returns its JSON record: ms per
/// batched tick, sheet-ticks and particle-substeps per second, and the speed-up over single-sheet
/// runs of the same size (`single_ms`, per tick).
nlohmann::json runBatchCase(const BenchOptions& o, const Size& size, const std::string& backend, uint32_t sheets,
                            double single_ms, const std::string& label, Progress& progress);

} // namespace tender::bench
