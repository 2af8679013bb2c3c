// `tender diff`: runs the same input on two backends and names the first tick, substep, pass and
// particle or constraint where their states part. Every tick's end states are compared; in the
// first tick that differs, a bisection over its passes replays both runs from the start and
// stops the tick after the probed pass (Solver::stopNextTickAfter).
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "commands.h"
#include "core/passes.h"
#include "core/sheet.h"
#include "core/simulation.h"
#include "core/stats.h"

namespace tender {

namespace {

/// One backend of the comparison and its run.
struct Side {
  std::string label;
  Backend backend;
  std::unique_ptr<Simulation> sim;
  SimState state;
  std::vector<glm::vec4> deltas;
};

/// Where two states first differ.
struct Difference {
  std::string what;            ///< "particle 17 pos.y", "constraint slot 4", ...
  std::string a, b;            ///< the two values
  std::optional<int64_t> ulps; ///< their distance, when they are floats
  size_t count = 0;            ///< particles (or records) that differ
};

// "cpu", "gpu", "gpu-percolor", each GPU kind with ":N" for device N.
std::optional<std::string> parseBackend(const std::string& text, const CommonOptions& common, BackendOptions& out) {
  std::string kind = text;
  int device = common.device;
  if (auto colon = text.find(':'); colon != std::string::npos) {
    kind = text.substr(0, colon);
    uint64_t n = 0;
    if (kind == "cpu" || parseWhole(text.substr(colon + 1), 0, 1024, n))
      return "backend '" + text + "': expected cpu, gpu, gpu:N, gpu-percolor or gpu-percolor:N";
    device = int(n);
  }
  if (kind != "cpu" && kind != "gpu" && kind != "gpu-percolor")
    return "unknown backend '" + text + "' (cpu, gpu, gpu:N, gpu-percolor or gpu-percolor:N)";
  out = backendOptionsFor(kind, common.params);
  out.device = device;
  out.validation = common.validation;
  return std::nullopt;
}

int64_t orderedBits(uint32_t bits) { return (bits & 0x80000000u) ? -int64_t(bits & 0x7FFFFFFFu) : int64_t(bits); }

uint32_t bitsOf(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

float floatOf(uint32_t u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

// The first differing component of two arrays of vec4 (per element, x y z w), and how many
// elements differ.
std::string showFloat(uint32_t bits) {
  char text[48];
  std::snprintf(text, sizeof text, "0x%08x %.9g", bits, double(floatOf(bits)));
  return text;
}

void compareVectors(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b, const char* name,
                    std::optional<Difference>& first, const char* element = "particle") {
  if (first) return;
  static const char* kAxis[4] = {"x", "y", "z", "w"};
  Difference d;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    for (int c = 0; c < 4; ++c)
      if (bitsOf(a[i][c]) != bitsOf(b[i][c])) {
        if (d.count++ == 0) {
          const uint32_t x = bitsOf(a[i][c]), y = bitsOf(b[i][c]);
          d.what = std::string(element) + " " + std::to_string(i) + " " + name + "." + kAxis[c];
          d.a = showFloat(x);
          d.b = showFloat(y);
          d.ulps = std::llabs(orderedBits(x) - orderedBits(y));
        }
        break;
      }
  if (a.size() != b.size() && d.count == 0) {
    d.what = std::string(name) + " count";
    d.a = std::to_string(a.size());
    d.b = std::to_string(b.size());
    d.count = 1;
  }
  if (d.count) first = d;
}

// The first differing record of two arrays (`show` prints one), and how many differ.
template <class T, class Show>
void compareRecords(const std::vector<T>& a, const std::vector<T>& b, const std::string& name, Show show,
                    std::optional<Difference>& first) {
  if (first) return;
  Difference d;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(T)) != 0 && d.count++ == 0) {
      d.what = name + " " + std::to_string(i);
      d.a = show(a[i]);
      d.b = show(b[i]);
    }
  if (a.size() != b.size() && d.count == 0) {
    d.what = name + " count";
    d.a = std::to_string(a.size());
    d.b = std::to_string(b.size());
    d.count = 1;
  }
  if (d.count) first = d;
}

// Where the states of the two sides first differ (nullopt: bitwise the same).
std::optional<Difference> compare(const Side& x, const Side& y, bool deltas) {
  std::optional<Difference> first;
  compareVectors(x.state.pos, y.state.pos, "pos", first);
  compareVectors(x.state.prev, y.state.prev, "prev", first);
  if (deltas) compareVectors(x.deltas, y.deltas, "collision delta", first);
  // A hinge's x: its rest angle, y: the yield its hardening added, z: its multiplier
  compareVectors(x.state.hinges, y.state.hinges, "state", first, "hinge");
  compareRecords(
      x.state.torn, y.state.torn, "torn flag of constraint",
      [](uint32_t t) { return std::string(t ? "torn" : "whole"); }, first);
  compareRecords(
      x.state.colors, y.state.colors, "colour",
      [](const ColorRange& c) { return "first " + std::to_string(c.first) + ", " + std::to_string(c.count) + " live"; },
      first);
  compareRecords(
      x.state.constraints, y.state.constraints, "constraint slot",
      [](const shaderio::Constraint& c) {
        return "particles " + std::to_string(c.a) + "-" + std::to_string(c.b) + ", kind " +
               std::to_string(c.kind_id & SIM_KIND_MASK) + ", id " + std::to_string(c.kind_id >> SIM_KIND_BITS) +
               ", rest " + showFloat(bitsOf(c.rest));
      },
      first);
  compareRecords(
      x.state.triangles, y.state.triangles, "live triangle",
      [](const glm::uvec4& t) {
        return std::to_string(t.x) + " " + std::to_string(t.y) + " " + std::to_string(t.z) + ", id " +
               std::to_string(t.w);
      },
      first);
  return first;
}

class Diff {
public:
  Diff(const CommonOptions& common, InputScript script, Side& a, Side& b)
      : common_(common), script_(std::move(script)), a_(a), b_(b) {}

  // Runs both sides from the start for `ticks` whole ticks (the next tick then stops after
  // pass `stop`, unless SIM_NONE).
  void replay(uint64_t ticks, uint32_t stop) {
    for (Side* s : {&a_, &b_}) {
      s->sim = std::make_unique<Simulation>(common_.params, *s->backend.solver);
      s->sim->setScript(script_);
      for (uint64_t t = 0; t < ticks; ++t) s->sim->tick();
      if (stop != SIM_NONE) {
        s->backend.solver->stopNextTickAfter(stop);
        s->sim->tick();
      }
    }
  }

  // Reads both states back (and the collision deltas) and compares them.
  std::optional<Difference> check(bool deltas) {
    for (Side* s : {&a_, &b_}) {
      s->backend.solver->finish();
      s->backend.solver->readback(s->state);
      if (deltas) s->backend.solver->readDeltas(s->deltas);
    }
    return compare(a_, b_, deltas);
  }

  // The first differing tick, or nullopt when the `ticks` ticks end identical.
  std::optional<uint64_t> firstDifferingTick(uint64_t ticks) {
    replay(0, SIM_NONE);
    for (uint64_t t = 0; t < ticks; ++t) {
      a_.sim->tick();
      b_.sim->tick();
      if ((last_ = check(false))) return t;
    }
    return std::nullopt;
  }

  // The first pass of tick `t` after which the states differ, and the difference there.
  uint32_t firstDifferingPass(uint64_t t, const shaderio::SimUniforms& u, Difference& where) {
    // Invariant: identical after pass lo (-1: the tick's start), different after pass hi.
    int64_t lo = -1, hi = int64_t(passesPerTick(u)) - 1;
    where = *last_;
    while (hi - lo > 1) {
      const int64_t mid = lo + (hi - lo) / 2;
      replay(t, uint32_t(mid));
      if (auto d = check(passAt(u, uint32_t(mid)).kind == PassKind::collide)) {
        hi = mid;
        where = *d;
      } else {
        lo = mid;
      }
    }
    return uint32_t(hi);
  }

private:
  const CommonOptions& common_;
  InputScript script_;
  Side &a_, &b_;
  std::optional<Difference> last_;
};

} // namespace

int runDiff(const CommonOptions& common, const DiffOptions& o) {
  std::string error;
  Side a, b;
  BackendOptions oa, ob;
  if (auto err = parseBackend(o.a, common, oa)) return fail("--a: " + *err);
  if (auto err = parseBackend(o.b, common, ob)) return fail("--b: " + *err);
  for (const BackendOptions* opt : {&oa, &ob})
    if (auto err = validate(common.params, opt->backend == "cpu" ? "cpu" : "gpu")) return fail(*err);
  // The sheets the script makes, checked once on the side that needs more memory (a GPU's)
  const bool gpu = oa.backend != "cpu" || ob.backend != "cpu";
  auto script = scriptFor(common.script, common.params, gpu ? "gpu" : "cpu", error);
  if (!script) return fail(error);
  // The test hook: a one-ULP change planted in the CPU side (b when both are)
  if (const char* plant = std::getenv("TENDER_TEST_PLANT_ULP"); plant && *plant) {
    auto p = parsePlantedUlp(plant, error);
    if (!p) return fail("TENDER_TEST_PLANT_ULP: " + error);
    if (p->particle >= common.params.particleCount())
      return fail("TENDER_TEST_PLANT_ULP: particle " + std::to_string(p->particle) + " is not on the sheet");
    BackendOptions* cpu = ob.backend == "cpu" ? &ob : oa.backend == "cpu" ? &oa : nullptr;
    if (!cpu) return fail("TENDER_TEST_PLANT_ULP needs a cpu side");
    // A pass the run never reaches would plant nothing and the sides would compare identical.
    if (p->tick >= o.ticks)
      return fail("TENDER_TEST_PLANT_ULP: tick " + std::to_string(p->tick) + " is not run (--ticks " +
                  std::to_string(o.ticks) + ")");
    shaderio::SimUniforms u{}; // what passIndex reads of a physics tick's uniforms
    u.substeps = common.params.substeps;
    u.iterations = common.params.iterations;
    u.color_count = buildSheet(common.params).colorCount();
    u.flags = common.params.collision ? SIM_FLAG_COLLISION : 0u;
    if (!passIndex(u, p->pass))
      return fail("TENDER_TEST_PLANT_ULP: no pass '" + describePass(p->pass) + "' in a tick of " +
                  std::to_string(shaderio::substepCount(u.substeps)) + " substeps, " + std::to_string(u.iterations) +
                  " iterations of " + std::to_string(u.color_count) + " colours, collision " +
                  ((u.flags & SIM_FLAG_COLLISION) ? "on" : "off"));
    cpu->plant = p;
  }
  a.label = o.a == o.b ? "a:" + o.a : o.a;
  b.label = o.a == o.b ? "b:" + o.b : o.b;
  for (auto [opt, side] : {std::pair{&oa, &a}, std::pair{&ob, &b}})
    if (auto err = createBackend(*opt, side->backend)) return fail(*err);

  Diff diff(common, *script, a, b);
  const auto tick = diff.firstDifferingTick(o.ticks);
  if (!tick) {
    std::printf("identical: %" PRIu64 " ticks, state hash %s\n", o.ticks, hashHex(hashPositions(a.state.pos)).c_str());
    return 0;
  }
  const shaderio::SimUniforms u = a.sim->lastUniforms();
  Difference d;
  const uint32_t pass = diff.firstDifferingPass(*tick, u, d);
  std::printf("differ: %s and %s part in tick %" PRIu64 ", %s (pass %u of %u)\n", a.label.c_str(), b.label.c_str(),
              *tick, describePass(passAt(u, pass)).c_str(), pass, passesPerTick(u));
  std::printf("  first difference: %s (%zu differ after that pass)\n", d.what.c_str(), d.count);
  std::printf("  %-12s %s\n  %-12s %s\n", a.label.c_str(), d.a.c_str(), b.label.c_str(), d.b.c_str());
  if (d.ulps) std::printf("  %" PRId64 " ULP apart\n", *d.ulps);
  if (*tick > 0) std::printf("  identical through tick %" PRIu64 "\n", *tick - 1);
  return 1;
}

} // namespace tender
