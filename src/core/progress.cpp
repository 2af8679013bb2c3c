#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace tender {

Progress::Progress(std::string label, std::string unit, uint64_t total, double delay_s)
    : Progress(std::move(label), std::move(unit), total, delay_s, stderr, isTerminal(stderr)) {}

Progress::Progress(std::string label, std::string unit, uint64_t total, double delay_s, std::FILE* out, bool on)
    : label_(std::move(label)), unit_(std::move(unit)), total_(total), delay_s_(delay_s), out_(out),
      on_(on && total > 0), start_(Clock::now()), last_(start_) {}

Progress::~Progress() { clear(); }

bool Progress::isTerminal(std::FILE* f) { return f && isatty(fileno(f)) == 1; }

void Progress::update(uint64_t done) {
  if (!on_) return;
  const auto now = Clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < delay_s_) return;
  if (shown_ && now - last_ < std::chrono::milliseconds(100) && done < total_) return;
  last_ = now;
  const std::string text = line(label_, unit_, std::min(done, total_), total_, elapsed);
  // Spaces cover the rest of a longer earlier line.
  const size_t pad = width_ > text.size() ? width_ - text.size() : 0;
  std::fprintf(out_, "\r%s%*s", text.c_str(), int(pad), "");
  std::fflush(out_);
  width_ = text.size();
  shown_ = true;
}

void Progress::clear() {
  if (!shown_) return;
  std::fprintf(out_, "\r\033[K");
  std::fflush(out_);
  shown_ = false;
  width_ = 0;
}

std::string Progress::clock(double seconds) {
  const uint64_t s = seconds > 0.0 && std::isfinite(seconds) ? uint64_t(std::llround(std::min(seconds, 3.6e8))) : 0;
  char buf[48];
  if (s >= 3600)
    std::snprintf(buf, sizeof(buf), "%llu:%02u:%02u", static_cast<unsigned long long>(s / 3600), unsigned(s / 60 % 60),
                  unsigned(s % 60));
  else
    std::snprintf(buf, sizeof(buf), "%u:%02u", unsigned(s / 60), unsigned(s % 60));
  return buf;
}

std::string Progress::line(const std::string& label, const std::string& unit, uint64_t done, uint64_t total,
                           double elapsed_s) {
  constexpr int kWidth = 30;
  const long double fraction = total ? (long double)std::min(done, total) / (long double)total : 1.0L;
  const int filled = int(fraction * kWidth);
  const int percent = int(fraction * 100);
  std::string bar(size_t(filled), '#');
  bar.append(size_t(kWidth - filled), '-');
  std::string eta = "--:--";
  if (done > 0) eta = clock(elapsed_s * double(total - std::min(done, total)) / double(done));
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%s: [%s] %3d%% %s %llu of %llu, %s left", label.c_str(), bar.c_str(), percent,
                unit.c_str(), static_cast<unsigned long long>(done), static_cast<unsigned long long>(total),
                eta.c_str());
  return buf;
}

} // namespace tender
