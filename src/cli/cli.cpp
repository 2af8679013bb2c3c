#include "cli.h"

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <iostream>

#include <CLI/CLI.hpp>

namespace tender {
namespace {

const char* program_name = "tender";
volatile std::sig_atomic_t caught_signal = 0;

extern "C" void onInterrupt(int signal) { caught_signal = signal; }

} // namespace

void setProgramName(const char* name) { program_name = name; }

int fail(const std::string& message) {
  const std::string line = std::string(program_name) + ": error: " + printable(message) + "\n";
  std::fwrite(line.data(), 1, line.size(), stderr);
  std::fflush(stderr);
  return kExitBadInput;
}

int finishOutput(int status) {
  std::cout.flush();
  errno = 0;
  const bool flushed = std::fflush(stdout) == 0;
  const int why = errno;
  if (flushed && !std::ferror(stdout) && !std::cout.fail()) return status;
  std::clearerr(stdout);
  fail(std::string("cannot write standard output") + (why ? std::string(": ") + std::strerror(why) : ""));
  return kExitBadInput;
}

std::optional<std::string> emptyValue(const CLI::App& app) {
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->count() == 0 || opt->get_expected_min() == 0) continue; // not given, or a flag
    for (const std::string& value : opt->results())
      if (value.empty()) return opt->get_name() + ": the value is empty";
  }
  for (const CLI::App* sub : app.get_subcommands())
    if (auto err = emptyValue(*sub)) return err;
  return std::nullopt;
}

std::optional<int> parseArgs(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) { // --help, --version
    return finishOutput(app.exit(e));
  } catch (const CLI::ParseError& e) {
    return fail(e.what());
  }
  if (auto err = emptyValue(app)) return fail(*err);
  return std::nullopt;
}

CLI::Validator finiteRange(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        double v = 0.0;
        if (!CLI::detail::lexical_cast(text, v) || !std::isfinite(v)) return "'" + text + "' is not a finite number";
        if (v < lo || v > hi)
          return text + " is out of range [" + CLI::detail::to_string(lo) + ", " + CLI::detail::to_string(hi) + "]";
        return {};
      },
      "FINITE in [" + CLI::detail::to_string(lo) + " - " + CLI::detail::to_string(hi) + "]");
}

void catchInterrupts() {
  struct sigaction sa {};
  sa.sa_handler = onInterrupt;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART; // the run looks at the flag between its steps
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &sa, nullptr);
}

bool interrupted() { return caught_signal != 0; }

std::string interruptMessage() {
  const int sig = caught_signal;
  const char* name = sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "a signal";
  return std::string("interrupted (") + name + ")";
}

} // namespace tender
