// `tender render --video`: every frame of a run rendered offscreen and piped to ffmpeg, which
// encodes an H.264 MP4 (yuv420p, moov atom first: it plays in a browser).
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numeric>
#include <string>
#include <vector>

#include "backend/headless.h"
#include "commands.h"
#include "core/output.h"
#include "core/progress.h"

namespace tender {
namespace {

using u128 = unsigned __int128;

/// Most frames of one video (46 hours at 60 fps).
constexpr uint64_t kMaxFrames = 10000000;

struct Rational {
  uint64_t num = 0, den = 1;
};

bool allDigits(const std::string& s) { return s.find_first_not_of("0123456789") == std::string::npos; }

// Parses a plain decimal ("30", "29.97") with at most `places` decimals as an exact fraction in
// (0, hi]; returns an error.
std::optional<std::string> parseDecimal(const std::string& s, int places, uint64_t hi, Rational& out) {
  const std::string body = !s.empty() && (s[0] == '-' || s[0] == '+') ? s.substr(1) : s;
  const size_t dot = body.find('.');
  const std::string whole = body.substr(0, dot), frac = dot == std::string::npos ? "" : body.substr(dot + 1);
  if (body.empty() || !allDigits(whole) || !allDigits(frac) || (whole.empty() && frac.empty()))
    return "'" + s + "' is not a number";
  const std::string range = " is out of range (0, " + std::to_string(hi) + "]";
  if (frac.size() > size_t(places)) return "'" + s + "' has more than " + std::to_string(places) + " decimals";
  const size_t first = whole.find_first_not_of('0');
  if (first != std::string::npos && whole.size() - first > 9) return s + range;
  Rational r;
  for (size_t i = 0; i < frac.size(); ++i) r.den *= 10;
  r.num = (whole.empty() ? 0 : std::stoull(whole)) * r.den + (frac.empty() ? 0 : std::stoull(frac));
  if (s[0] == '-' || r.num == 0 || r.num > hi * r.den) return s + range;
  const uint64_t g = std::gcd(r.num, r.den);
  out = {r.num / g, r.den / g};
  return std::nullopt;
}

// The exact value of a float tick rate (at least 1) as a fraction m / 2^k.
Rational exactRate(float hz) {
  int e = 0;
  const float f = std::frexp(hz, &e); // hz = f 2^e, f in [0.5, 1)
  Rational r{uint64_t(std::ldexp(f, 24)), 1};
  int shift = 24 - e;
  for (; shift > 0 && r.num % 2 == 0; --shift) r.num /= 2;
  for (; shift < 0; ++shift) r.num *= 2;
  r.den = uint64_t(1) << shift;
  return r;
}

// The first executable `name` on PATH; empty when none.
std::string findProgram(const std::string& name) {
  const char* env = std::getenv("PATH");
  const std::string path = env && *env ? env : "/usr/local/bin:/usr/bin:/bin";
  for (size_t start = 0; start <= path.size();) {
    size_t end = path.find(':', start);
    if (end == std::string::npos) end = path.size();
    std::string dir = path.substr(start, end - start);
    const std::string candidate = (dir.empty() ? std::string(".") : dir) + "/" + name;
    struct stat st {};
    if (stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) && access(candidate.c_str(), X_OK) == 0)
      return candidate;
    start = end + 1;
  }
  return "";
}

// ffmpeg reading raw frames on a pipe. Its messages (errors only) go to an anonymous file: any
// message is a failure, as ffmpeg may exit with status 0 after a failed write of the file's end.
class Encoder {
public:
  Encoder() = default;
  Encoder(const Encoder&) = delete;
  Encoder& operator=(const Encoder&) = delete;
  ~Encoder() { stop(); }

  std::optional<std::string> start(const std::string& program, const std::vector<std::string>& args) {
    log_ = std::tmpfile();
    if (!log_) return std::string("cannot start ffmpeg: ") + std::strerror(errno);
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) return std::string("cannot start ffmpeg: ") + std::strerror(errno);
    const int null = open("/dev/null", O_RDWR | O_CLOEXEC);
    std::vector<char*> argv;
    std::vector<std::string> all = args;
    all.insert(all.begin(), "ffmpeg");
    for (std::string& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::fflush(nullptr);
    pid_ = fork();
    if (pid_ == 0) {
      // Its own process group: Ctrl-C reaches tender, which stops ffmpeg and removes the file.
      setpgid(0, 0);
      for (int sig : {SIGPIPE, SIGINT, SIGTERM, SIGHUP}) std::signal(sig, SIG_DFL);
      dup2(fds[0], 0);
      if (null >= 0) dup2(null, 1);
      dup2(fileno(log_), 2);
      execv(program.c_str(), argv.data());
      std::fprintf(stderr, "cannot run %s: %s\n", program.c_str(), std::strerror(errno));
      _exit(127);
    }
    const int saved = errno;
    close(fds[0]);
    if (null >= 0) close(null);
    if (pid_ < 0) {
      close(fds[1]);
      return std::string("cannot start ffmpeg: ") + std::strerror(saved);
    }
    in_ = fds[1];
    return std::nullopt;
  }

  // Sends bytes to ffmpeg; false when it has stopped reading (it failed).
  bool write(const uint8_t* data, size_t size) {
    while (size > 0) {
      const ssize_t n = ::write(in_, data, size);
      if (n < 0) {
        if (errno == EINTR) continue;
        return false;
      }
      data += n;
      size -= size_t(n);
    }
    return true;
  }

  // Ends the input and waits for ffmpeg; its first error when it did not succeed.
  std::optional<std::string> finish() {
    if (in_ >= 0) close(in_), in_ = -1;
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0)
      if (errno != EINTR) return std::string("ffmpeg: ") + std::strerror(errno);
    pid_ = -1;
    std::string line = firstLine();
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && line.empty()) return std::nullopt;
    if (line.empty())
      line = WIFEXITED(status) ? "exited with status " + std::to_string(WEXITSTATUS(status))
                               : "killed by signal " + std::to_string(WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    return "ffmpeg: " + line;
  }

  // Stops ffmpeg without waiting for its file.
  void stop() {
    if (in_ >= 0) close(in_), in_ = -1;
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      while (waitpid(pid_, nullptr, 0) < 0 && errno == EINTR) {
      }
      pid_ = -1;
    }
    if (log_) std::fclose(log_), log_ = nullptr;
  }

private:
  std::string firstLine() {
    std::string text;
    std::rewind(log_);
    char buf[4096];
    size_t n = 0;
    while ((n = std::fread(buf, 1, sizeof(buf), log_)) > 0) text.append(buf, n);
    const size_t begin = text.find_first_not_of(" \r\n\t");
    if (begin == std::string::npos) return "";
    const size_t end = text.find_first_of("\r\n", begin);
    std::string line = text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    while (!line.empty() && (line.back() == ' ' || line.back() == '-')) line.pop_back();
    return line;
  }

  pid_t pid_ = -1;
  int in_ = -1;
  std::FILE* log_ = nullptr;
};

/// The video's frames (and `limit`, the ticks of its last frame, when given in ticks) at `fps`, with
/// p / q ticks a frame: --seconds (5 s with neither it, --ticks nor a script) x fps, rounded to the
/// nearest frame; or --ticks N, or the script's last event and one second after it, the last frame
/// showing tick N.
std::optional<std::string> videoLength(const CommonOptions& common, const RenderOptions& o, const InputScript& script,
                                       Rational fps, u128 p, u128 q, u128& frames, u128& limit) {
  if (!o.seconds.empty() || (!o.ticks_given && common.script.empty())) {
    Rational seconds{5, 1};
    if (!o.seconds.empty())
      if (auto err = parseDecimal(o.seconds, 3, 1000000, seconds)) return "--seconds: " + *err;
    frames = (u128(2) * seconds.num * fps.num + u128(seconds.den) * fps.den) / (u128(2) * seconds.den * fps.den);
    return std::nullopt;
  }
  limit = o.ticks_given
              ? o.ticks
              : (script.events.empty() ? 0 : script.events.back().tick) + uint64_t(std::ceil(common.params.tick_hz));
  frames = (limit * q + p - 1) / p;
  return std::nullopt;
}

/// ffmpeg's arguments: raw RGBA frames of `size` at `rate` on stdin, H.264 in 4:2:0 out to
/// `target`, the index first, an MP4 whatever the file's name.
std::vector<std::string> ffmpegArgs(const std::string& size, const std::string& rate, const std::string& target) {
  std::vector<std::string> args = {"-hide_banner", "-nostats", "-loglevel", "error", "-y"};
  args.insert(args.end(), {"-f", "rawvideo", "-pix_fmt", "rgba", "-video_size", size, "-framerate", rate});
  args.insert(args.end(), {"-i", "pipe:0"});
  args.insert(args.end(), {"-an", "-c:v", "libx264", "-pix_fmt", "yuv420p", "-movflags", "+faststart"});
  args.insert(args.end(), {"-f", "mp4", target});
  return args;
}

} // namespace

int runVideo(const CommonOptions& common, const RenderOptions& o) {
  // Frames, and the ticks before each: tick_hz / fps ticks per frame, accumulated exactly.
  Rational fps;
  if (auto err = parseDecimal(o.fps, 3, 240, fps)) return fail("--fps: " + *err);
  const Rational hz = exactRate(common.params.tick_hz);
  // Ticks per frame p / q.
  const u128 p = u128(hz.num) * fps.den, q = u128(hz.den) * fps.num;
  std::string error;
  auto script = scriptFor(common.script, common.params, common.backend, error);
  if (!script) return fail(error);
  u128 frames = 0, limit = ~u128(0); // limit: the ticks of the last frame, when given in ticks
  if (auto err = videoLength(common, o, *script, fps, p, q, frames, limit)) return fail(*err);
  if (frames == 0) return fail("the video has no frames (its length is below one frame)");
  auto ticksBefore = [&](uint64_t frame) { return uint64_t(std::min(u128(frame + 1) * p / q, limit)); };
  if (frames > kMaxFrames) return fail("a video of more than " + std::to_string(kMaxFrames) + " frames is too long");
  if (ticksBefore(uint64_t(frames) - 1) > kMaxTicks)
    return fail("a video of more than " + std::to_string(kMaxTicks) + " ticks is too long");
  if (o.width % 2 || o.height % 2)
    return fail("--video needs an even --width and --height (H.264 4:2:0), not " + std::to_string(o.width) + "x" +
                std::to_string(o.height));

  OutputSet outputs;
  if (auto err = outputs.add(o.video)) return fail(*err);
  const std::string ffmpeg = findProgram("ffmpeg");
  if (ffmpeg.empty()) return fail("--video needs ffmpeg, which is not on PATH (Debian: apt-get install ffmpeg)");

  render::HeadlessOptions h;
  headlessOptionsFor(common, o, *script, h);

  // A failed ffmpeg closes its end of the pipe: that is an error to report, not a signal.
  std::signal(SIGPIPE, SIG_IGN);
  // SIGINT, SIGTERM or SIGHUP: the run stops after the frame at hand, removing its file.
  catchInterrupts();
  const std::string rate = std::to_string(fps.num) + "/" + std::to_string(fps.den);
  const std::string size = std::to_string(o.width) + "x" + std::to_string(o.height);
  std::optional<std::string> render_error;
  uint32_t validation_messages = 0;
  // A bar on stderr while it is a terminal; nothing otherwise.
  Progress progress("tender render", "frame", uint64_t(frames));
  auto staged = outputs.stageAt(o.video, [&](const std::string& target) -> std::optional<std::string> {
    Encoder encoder;
    if (auto err = encoder.start(ffmpeg, ffmpegArgs(size, rate, target))) return err;
    std::optional<std::string> encoder_error;
    render::FrameSequence seq;
    seq.frames = uint64_t(frames);
    seq.ticks_before = ticksBefore;
    seq.sink = [&](const render::Picture& picture, uint64_t frame) -> std::optional<std::string> {
      if (interrupted()) {
        render_error = "interrupted; no video written";
        return render_error;
      }
      if (!encoder.write(picture.rgba.data(), picture.rgba.size())) {
        encoder_error = encoder.finish();
        if (!encoder_error) encoder_error = "ffmpeg stopped reading frames";
        return encoder_error;
      }
      progress.update(frame + 1);
      return std::nullopt;
    };
    if (auto err = render::renderSequence(h, seq, &validation_messages)) {
      if (encoder_error) return encoder_error;
      render_error = err;
      return err;
    }
    return encoder.finish();
  });
  progress.clear();
  if (render_error) return fail(*render_error);
  if (staged) return fail(*staged);
  if (auto err = outputs.commit()) return fail(*err);
  std::printf("tender render: %s (%ux%u, %llu frames at %s fps, %llu ticks, preset %s, backend %s)\n", o.video.c_str(),
              o.width, o.height, static_cast<unsigned long long>(frames), o.fps.c_str(),
              static_cast<unsigned long long>(ticksBefore(uint64_t(frames) - 1)), common.params.preset.c_str(),
              common.backend.c_str());
  if (common.validation && validation_messages > 0)
    return fail(std::to_string(validation_messages) + " validation messages");
  return 0;
}

} // namespace tender
