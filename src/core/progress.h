#pragma once
/// A progress bar for long jobs, drawn on a terminal only: one line on stderr rewritten in place
/// with \r (done/total, a bar, the percentage and an estimate of the time left), redrawn at most
/// ten times a second and cleared at the end. When stderr is not a terminal it prints nothing.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <string>

namespace tender {

class Progress {
public:
  /// `label` starts the line ("tender sim"), `unit` names a step ("tick"); `delay_s`: nothing is
  /// drawn before the job has run this long (a short job stays quiet).
  Progress(std::string label, std::string unit, uint64_t total, double delay_s = 0.0);
  /// The same on `out`, drawn when `on` (tests).
  Progress(std::string label, std::string unit, uint64_t total, double delay_s, std::FILE* out, bool on);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// `done` of the total steps are done; draws when due.
  void update(uint64_t done);
  /// Erases the line (when one was drawn).
  void clear();
  bool enabled() const { return on_; }

  /// Whether `f` is a terminal.
  static bool isTerminal(std::FILE* f);
  /// The line drawn: "tender sim: [#####-----]  50% tick 60 of 120, 0:02 left".
  static std::string line(const std::string& label, const std::string& unit, uint64_t done, uint64_t total,
                          double elapsed_s);
  /// "0:07", "12:34", "1:02:03": seconds as [h:]m:ss.
  static std::string clock(double seconds);

private:
  using Clock = std::chrono::steady_clock;
  std::string label_, unit_;
  uint64_t total_;
  double delay_s_;
  std::FILE* out_;
  bool on_, shown_ = false;
  Clock::time_point start_, last_;
  size_t width_ = 0; ///< the length of the line last drawn
};

} // namespace tender
