// `tender` with no subcommand: the interactive demo (a separate program, so that `tender` itself
// links no window system) when a display is there; otherwise a headless render to a PNG.
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "commands.h"
#include "core/output.h"

namespace tender {
namespace {

bool hasDisplay() {
  for (const char* v : {"DISPLAY", "WAYLAND_DISPLAY"}) {
    const char* s = std::getenv(v);
    if (s && *s) return true;
  }
  return false;
}

// The arguments this process was started with.
std::vector<std::string> ownArguments() {
  std::ifstream f("/proc/self/cmdline", std::ios::binary);
  std::string all((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::vector<std::string> args;
  for (size_t i = 0; i < all.size();) {
    size_t end = all.find('\0', i);
    if (end == std::string::npos) end = all.size();
    args.push_back(all.substr(i, end - i));
    i = end + 1;
  }
  return args;
}

// The demo this process waits for: the signals that end a session reach it (forwardToDemo).
volatile std::sig_atomic_t demo_pid = 0;
constexpr int kForwarded[] = {SIGINT, SIGTERM, SIGHUP};

extern "C" void forwardToDemo(int sig) {
  if (demo_pid > 0) kill(pid_t(demo_pid), sig);
}

// Runs tender-demo with this process's arguments and waits for it: its exit status, or
// kExitNoWindow when it could not be started or could not open a window. SIGINT, SIGTERM and
// SIGHUP sent to this process alone (a supervisor's, `timeout`'s, a desktop's) are passed on to the
// demo, which ends its session as a window close does; a terminal's Ctrl-C reaches both, and the
// demo takes the second as the first.
int launchDemo(const std::filesystem::path& demo) {
  std::vector<std::string> args = ownArguments();
  if (args.empty()) args.push_back("tender");
  args[0] = demo.string();
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(nullptr);
  // Held until the handlers know the child: a signal meanwhile waits, and is then passed on
  sigset_t forwarded, before;
  sigemptyset(&forwarded);
  for (int sig : kForwarded) sigaddset(&forwarded, sig);
  sigprocmask(SIG_BLOCK, &forwarded, &before);
  const pid_t child = fork();
  if (child == 0) {
    sigprocmask(SIG_SETMASK, &before, nullptr);
    setenv(kLaunchedVariable, "1", 1);
    execv(demo.c_str(), argv.data());
    std::fprintf(stderr, "tender: cannot start %s; rendering a picture instead\n", demo.c_str());
    _exit(kExitNoWindow);
  }
  if (child < 0) {
    sigprocmask(SIG_SETMASK, &before, nullptr);
    std::fprintf(stderr, "tender: cannot start %s; rendering a picture instead\n", demo.c_str());
    return kExitNoWindow;
  }
  demo_pid = child;
  struct sigaction sa {
  }, old[std::size(kForwarded)];
  sa.sa_handler = forwardToDemo;
  sigemptyset(&sa.sa_mask);
  for (size_t k = 0; k < std::size(kForwarded); ++k) sigaction(kForwarded[k], &sa, &old[k]);
  sigprocmask(SIG_SETMASK, &before, nullptr);
  int status = 0;
  pid_t waited;
  while ((waited = waitpid(child, &status, 0)) < 0 && errno == EINTR) {
  }
  for (size_t k = 0; k < std::size(kForwarded); ++k) sigaction(kForwarded[k], &old[k], nullptr);
  demo_pid = 0;
  if (waited < 0) return kExitBadInput;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

} // namespace

const char* const kProgramName = "tender";

int runDemo(const CommonOptions& common, const DemoOptions& o) {
  std::error_code ec;
  const std::filesystem::path demo = std::filesystem::read_symlink("/proc/self/exe", ec).parent_path() / "tender-demo";
  // With a display, the demo; when it cannot open a window there (an unreachable display), it
  // says so in one line and the picture is rendered as with no display.
  const bool display = hasDisplay();
  if (display) {
    if (!ec && std::filesystem::exists(demo)) {
      const int status = launchDemo(demo);
      if (status != kExitNoWindow) return status;
    } else {
      std::printf("tender: this build has no tender-demo; rendering a picture instead\n");
    }
  }
  // No display: one picture of the preset after two seconds of simulation, or at --quit-at's step
  // (of the replayed session, with --replay); --record writes the input of that session.
  RenderOptions r;
  r.width = o.width;
  r.height = o.height;
  r.ticks = o.quit_at > 0 ? o.quit_at : uint64_t(2.0f * common.params.tick_hz);
  r.out = "tender.png";
  std::string error;
  std::optional<InputScript> replay = scriptFor(o.replay, common.params, common.backend, error);
  if (!replay) return fail(error);
  OutputSet record;
  if (auto err = record.addInput(o.replay)) return fail(*err);
  if (auto err = record.add(o.record)) return fail(*err);
  CommonOptions session = common;
  session.script = o.replay;
  if (!display) std::printf("tender: no display; rendering a picture instead\n");
  int status = runRender(session, r);
  if (status != 0) return status;
  if (!o.record.empty()) {
    std::string text = "# tender input script, preset " + common.params.preset + " (headless session)\n";
    for (const ScriptEvent& e : replay->events)
      if (e.tick < r.ticks) text += formatEvent(e) + "\n";
    if (auto err = record.stage(o.record, text)) return fail(*err);
    if (auto err = record.commit()) return fail(*err);
  }
  std::printf("tender: wrote %s\n", std::filesystem::absolute(r.out, ec).string().c_str());
  return 0;
}

} // namespace tender
