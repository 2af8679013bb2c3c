#pragma once
/// What every program of Tender (tender, tender-demo, tender-bench) does with an error, its standard
/// output, an empty option value and an interrupt: one line `<program>: error: <message>` of
/// printable text and exit status 2.
#include <optional>
#include <string>

#include "core/text.h" // printable()

// CLI11's types, declared only: what parses a command line includes <CLI/CLI.hpp> itself, and the
// commands, which only report errors, are spared compiling it (about 8 s a translation unit).
namespace CLI {
class App;
class Validator;
} // namespace CLI

namespace tender {

/// Exit status of every error (bad input, a fault, an interrupt), with one line on stderr.
constexpr int kExitBadInput = 2;

/// The name error lines start with ("tender" unless set).
void setProgramName(const char* name);
/// Prints "<program>: error: <message>" (printable) and returns kExitBadInput.
int fail(const std::string& message);
/// Flushes standard output; when anything written there was lost (a full disk, a closed pipe),
/// prints "cannot write standard output: <why>" and returns kExitBadInput, else `status`.
int finishOutput(int status);
/// The first option of `app` or of its subcommands in use that was given an empty value, as
/// "--video: the value is empty"; nullopt when none was.
std::optional<std::string> emptyValue(const CLI::App& app);
/// Parses the command line into `app`: the exit status when the run ends there (--help and
/// --version printed, or a bad or empty option's one line), nothing when it goes on.
std::optional<int> parseArgs(CLI::App& app, int argc, char** argv);
/// A check for CLI11: a finite number in [lo, hi] (CLI::Range lets NaN through).
CLI::Validator finiteRange(double lo, double hi);

/// From now on SIGINT, SIGTERM and SIGHUP set a flag (interrupted()) instead of ending the
/// process, so that a long run can stop, remove its temporary files and say so.
void catchInterrupts();
/// True once one of those signals arrived.
bool interrupted();
/// "interrupted (SIGINT)": the signal that arrived.
std::string interruptMessage();

} // namespace tender
