#pragma once
/// Fleets: many sheets of one grid that tick together. Each sheet has its own parameters, input
/// script and Simulation; a SheetBatch runs the ticks of all of them at once (the CPU reference
/// spreads the sheets over its threads, the GPU runs every small sheet's whole tick in one
/// dispatch). Sheet i of a fleet ends in exactly the state the same sheet reaches run alone on
/// the same backend.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "params.h"
#include "script.h"
#include "simulation.h"
#include "solver.h"

namespace tender {

/// The solvers of B sheets that run their ticks as one batch.
class SheetBatch {
public:
  virtual ~SheetBatch() = default;
  /// Backend name ("cpu", "gpu").
  virtual std::string name() const = 0;
  /// Number of sheets.
  virtual uint32_t size() const = 0;
  /// The solver of sheet i. Its tick() queues the tick; any other call runs the queued ticks of
  /// every sheet first (so a grab reads the position after the ticks before it).
  virtual Solver& sheet(uint32_t i) = 0;
  /// Runs every queued tick, the sheets' at once.
  virtual void flush() = 0;
  /// Waits until the ticks run so far have finished.
  virtual void finish() = 0;
  /// Bytes of device (or host) memory the sheets' arrays take.
  virtual uint64_t memoryBytes() const = 0;
  /// Dispatches (GPU) or sheet jobs (CPU) of the last flush.
  virtual uint32_t dispatchesPerFlush() const = 0;
  /// Every sheet's positions and previous positions, sheet after sheet (size() x N each), in one
  /// read-back where the backend can (runs the queued ticks first).
  virtual void readPositions(std::vector<glm::vec4>& pos, std::vector<glm::vec4>& prev);
};

/// One sheet of a fleet: its parameters and its input script (empty: none).
struct FleetSheet {
  SimParams params;
  InputScript script;
};

/// The keys of SimParams that change a sheet's topology (its grid, rest lengths and constraint
/// families): the sheets of one batch must agree on them, and a sweep cannot vary them.
const std::vector<std::string>& topologyKeys();
/// Why sheets with these parameters cannot share a batch (the first topology key they differ
/// in); nullopt when they can.
std::optional<std::string> batchMismatch(const SimParams& a, const SimParams& b);

/// B Simulations on one SheetBatch.
class Fleet {
public:
  /// Builds and uploads every sheet (sheets.size() == batch.size(); the sheets must agree on the
  /// topology keys); the batch must outlive the fleet.
  Fleet(SheetBatch& batch, const std::vector<FleetSheet>& sheets);
  /// One step of every sheet (Simulation::tick: its due script events, then a physics tick, a
  /// reset frame or nothing when paused), the ticks run as one batch.
  void tick();
  uint32_t size() const { return uint32_t(sims_.size()); }
  Simulation& sim(uint32_t i) { return *sims_[i]; }
  SheetBatch& batch() { return batch_; }

private:
  SheetBatch& batch_;
  std::vector<std::unique_ptr<Simulation>> sims_;
};

/// A Solver that queues its ticks for a batch: tick() stores the uniforms, every other call runs
/// the batch's queued ticks (SheetBatch::flush) and then goes to the sheet's own solver. The CPU
/// batch wraps one CpuSolver per sheet in it.
class QueuedSolver final : public Solver {
public:
  QueuedSolver(SheetBatch& batch, Solver& inner) : batch_(batch), inner_(inner) {}
  /// The queued tick, if any (the batch runs and clears it).
  std::optional<shaderio::SimUniforms>& queued() { return queued_; }
  Solver& inner() { return inner_; }

  std::string name() const override { return inner_.name(); }
  void upload(const SheetTopology& topo) override;
  void tick(const shaderio::SimUniforms& u) override;
  void beginReset() override;
  void computeNormals() override;
  shaderio::PickResult pick(glm::vec3 o, glm::vec3 d, float radius) override;
  glm::vec3 particlePosition(uint32_t index) override;
  std::vector<glm::vec3> particlePositions(const std::vector<uint32_t>& indices) override;
  void readback(SimState& out) override;
  void finish() override;
  uint32_t dispatchesPerTick() const override { return inner_.dispatchesPerTick(); }
  int64_t contacts() const override { return inner_.contacts(); }
  uint64_t memoryBytes() const override { return inner_.memoryBytes(); }
  Arithmetic arithmetic() const override { return inner_.arithmetic(); }
  void stopNextTickAfter(uint32_t last_pass) override;
  void readDeltas(std::vector<glm::vec4>& out) override;

private:
  SheetBatch& batch_;
  Solver& inner_;
  std::optional<shaderio::SimUniforms> queued_;
};

} // namespace tender
