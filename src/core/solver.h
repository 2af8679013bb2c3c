#pragma once
/// The interface both solvers implement, and the state they read back.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sheet.h"

namespace tender {

/// A solver's full state, read back for tests, stats and files.
struct SimState {
  std::vector<glm::vec4> pos, prev;              ///< w = inverse mass of the last substep
  std::vector<glm::vec4> normal;                 ///< from the last normals pass
  std::vector<shaderio::Constraint> constraints; ///< live constraints, colour ranges compacted in place
  std::vector<ColorRange> colors;                ///< first stays, count shrinks as constraints tear
  std::vector<uint32_t> torn;                    ///< per original constraint id: 1 when torn
  std::vector<glm::vec4> hinges;                 ///< per hinge (HingeState): rest angle, added yield, multiplier
  std::vector<glm::uvec4> triangles;             ///< live triangles (first triangle_count entries)
  uint32_t triangle_count = 0;
};

/// Per-pass GPU times of the last measured tick, in milliseconds.
struct PassTimes {
  std::vector<std::pair<std::string, double>> ms;
  /// The same tick by kernel, where the solver times its dispatches apart (GpuSolver::timeKernels;
  /// the per-colour passes), else empty: each kernel that ran, and the sum of its dispatches.
  std::vector<std::pair<std::string, double>> kernels;
};

/// How a backend's float arithmetic runs (the stats JSON and `tender diff` report it).
struct Arithmetic {
  std::string rounding = "nearest even"; ///< "nearest even", or "device default" where it cannot be asked for
  std::string denormals = "flush to zero (FTZ, DAZ)"; ///< the CPU's; a device's "flush to zero (device)" or "(shader)"
  bool inexact_math_emulated = false;                 ///< sqrt and divide start from deliberately inexact ones
  bool corrected = true;                              ///< sqrt and divide corrected to the correctly rounded result
};

/// A simulation backend: the CPU reference or the Vulkan compute solver.
/// Both run the same passes in the same order on the same arrays.
class Solver {
public:
  virtual ~Solver() = default;
  /// Backend name ("cpu", "gpu").
  virtual std::string name() const = 0;
  /// (Re)initialises every array from the topology: particles at rest, all constraints alive.
  virtual void upload(const SheetTopology& topo) = 0;
  /// Runs one tick (all substeps) with these inputs; reset_active ticks run the reset pass only.
  virtual void tick(const shaderio::SimUniforms& u) = 0;
  /// Starts an animated reset: the current positions become the reset source, constraints and
  /// triangles are restored.
  virtual void beginReset() = 0;
  /// Recomputes the normals (once per frame, before drawing or reading back).
  virtual void computeNormals() = 0;
  /// Nearest particle to the ray o + t d (|d| = 1) within radius (index SIM_NONE: none), with its
  /// ray parameter and position: a grab costs this one round trip.
  virtual shaderio::PickResult pick(glm::vec3 o, glm::vec3 d, float radius) = 0;
  /// Position of one particle (a small read-back, used when a grab starts).
  virtual glm::vec3 particlePosition(uint32_t index) = 0;
  /// Positions of several particles, in one read-back where the backend can.
  virtual std::vector<glm::vec3> particlePositions(const std::vector<uint32_t>& indices) {
    std::vector<glm::vec3> out;
    for (uint32_t i : indices) out.push_back(particlePosition(i));
    return out;
  }
  /// Copies the whole state to the host.
  virtual void readback(SimState& out) = 0;
  /// Waits until every tick submitted so far has finished (the GPU runs asynchronously; the CPU
  /// has finished when tick() returns).
  virtual void finish() {}
  /// GPU time per pass of the last tick (empty on the CPU).
  virtual PassTimes passTimes() const { return {}; }
  /// Dispatches (or pass invocations) recorded per tick.
  virtual uint32_t dispatchesPerTick() const { return 0; }
  /// The workgroup barriers of the last tick of a sheet alone that one workgroup ran whole (the
  /// GPU's fused tick, where a barrier takes a dispatch's place); 0 where it ran as dispatches, in
  /// a fleet, or on the CPU. Waits for the tick.
  virtual uint32_t barrierPhasesPerTick() { return 0; }
  /// With contact on: the particles within the contact radius of a primitive at the start of the
  /// last substep (-1: the solver has no contact, or it is off).
  virtual int64_t contacts() const { return -1; }
  /// Bytes of device (or host) memory the solver's arrays take.
  virtual uint64_t memoryBytes() const { return 0; }
  /// How its float arithmetic runs (the CPU reference: IEEE, round to nearest even, denormals kept).
  virtual Arithmetic arithmetic() const { return {}; }
  /// Diagnosis (`tender diff`): the next physics tick runs its passes 0..last_pass only (numbered
  /// as passAt in passes.h) and stops there; SIM_NONE runs whole ticks. After a tick cut short
  /// the state is fit for readback() and readDeltas() only: start again with upload().
  virtual void stopNextTickAfter(uint32_t last_pass) = 0;
  /// Each particle's collision delta from the last collide pass (xyz, w = 0).
  virtual void readDeltas(std::vector<glm::vec4>& out) = 0;
};

} // namespace tender
