// `tender sweep`: many sheets of one grid, each with its own values of the varied parameters (a
// grid of every combination, or random samples; sweep_plan.h), run in batches that tick together
// (a Fleet per batch); one JSON line of `tender sim`'s stats per sheet. `--shard i/n` runs every
// n-th sheet, so shards run anywhere; `tender sweep-merge` joins their files into the whole sweep's.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "core/fleet.h"
#include "core/input_file.h"
#include "core/output.h"
#include "core/progress.h"
#include "core/simulation.h"
#include "core/stats.h"
#include "sweep_plan.h"

namespace tender {
namespace {

using namespace sweep;

/// Stats fields that describe how a sheet's batch ran rather than the sheet: a sweep writes them
/// under "batch", so that everything else on a line depends on the sheet alone.
const char* const kBatchFields[] = {"ms_per_tick", "ms_slowest_tick", "dispatches_per_tick", "gpu_ms_per_pass"};

/// Refuses a folder that holds another shard of the same sweep: two shards given one --out would
/// replace each other's results.
std::optional<std::string> otherShardIn(const std::string& dir, const Json& def) {
  std::string text;
  if (readInputFile(dir + "sweep.json", kMaxDefinitionBytes, text)) return std::nullopt; // none there
  const Json there = Json::parse(text, nullptr, false);
  if (!there.is_object() || definitionMismatch(def, there) || there["shard"] == def["shard"]) return std::nullopt;
  return "'" + dir + "' holds shard " + (there["shard"].is_string() ? there["shard"].get<std::string>() : "?") +
         " of this sweep: give each shard its own folder (and join them with `tender sweep-merge`)";
}

/// Runs a shard's sheets batch by batch and keeps each one's line (and PLY).
class Runner {
public:
  Runner(const CommonOptions& common, const Plan& plan, const InputScript& script, const std::string& dir, bool ply,
         OutputSet& outputs, Progress& progress)
      : common_(common), plan_(plan), script_(script), dir_(dir), ply_(ply), outputs_(outputs), progress_(progress) {}

  /// Runs every sheet of `indices` in batches of plan.batch.
  std::optional<std::string> run(const std::vector<uint64_t>& indices) {
    std::vector<SweepSheet> pending;
    for (uint64_t index : indices) {
      SweepSheet sheet;
      if (auto err = makeSheet(plan_, index, sheet)) return err;
      pending.push_back(std::move(sheet));
      if (pending.size() == plan_.batch) {
        if (auto err = runBatch(pending)) return err;
        pending.clear();
      }
    }
    if (!pending.empty()) return runBatch(pending);
    return std::nullopt;
  }

  /// The lines, sorted by index.
  std::string lines() {
    std::sort(lines_.begin(), lines_.end());
    std::string text;
    for (auto& [index, line] : lines_) text += line + "\n";
    return text;
  }

private:
  BackendOptions optionsFor(const SimParams& params) const {
    BackendOptions b = backendOptionsFor(plan_.backend, params);
    b.device = common_.device;
    b.validation = common_.validation;
    return b;
  }

  std::optional<std::string> runBatch(const std::vector<SweepSheet>& sheets) {
    std::unique_ptr<SheetBatch> batch;
    if (auto err = createBatch(optionsFor(sheets.front().params), uint32_t(sheets.size()), batch)) return err;
    std::vector<FleetSheet> fleet_sheets;
    for (const SweepSheet& s : sheets) fleet_sheets.push_back({s.params, script_});
    Fleet fleet(*batch, fleet_sheets);
    std::vector<double> ms;
    const bool ran = timedTicks(sheets.size(), ms, [&] {
      fleet.tick();
      batch->finish();
    });
    if (!ran) return interruptMessage() + "; nothing written";
    for (uint32_t i = 0; i < fleet.size(); ++i)
      if (auto err = record(sheets[i], fleet.sim(i), ms, batch->name() == "gpu", fleet.size())) return err;
    return std::nullopt;
  }

  /// Runs `tick` (one tick of `sheets` sheets, finished) the plan's number of times and keeps the
  /// wall time of each (ms); false when an interrupt stopped it.
  bool timedTicks(uint64_t sheets, std::vector<double>& ms, const std::function<void()>& tick) {
    for (uint64_t t = 0; t < plan_.ticks; ++t) {
      if (interrupted()) return false;
      const auto t0 = std::chrono::steady_clock::now();
      tick();
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      progress_.update(done_ += sheets);
    }
    return true;
  }

  /// The sheet's line: its index, its values, its stats (`tender sim --stats`'s fields) and under
  /// "batch" how its batch ran: the batch's sheets, dispatches, and its median and slowest batched
  /// tick in ms.
  std::optional<std::string> record(const SweepSheet& sheet, Simulation& sim, std::vector<double> ms, bool gpu,
                                    uint32_t batch_sheets) {
    Solver& solver = sim.solver();
    solver.computeNormals();
    SimState state;
    solver.readback(state);
    const SheetStats st = computeStats(state, sim.lastSubstepDt());
    const nlohmann::json stats =
        runStatsJson(st, solver, {sim.params().preset, plan_.ticks, sim.physicsTicks(), std::move(ms)}, gpu);
    Json line, batch;
    line["index"] = sheet.index;
    line["values"] = sheet.values;
    batch["sheets"] = batch_sheets;
    for (auto& [key, value] : stats.items()) {
      const bool of_batch = std::find(std::begin(kBatchFields), std::end(kBatchFields), key) != std::end(kBatchFields);
      (of_batch ? batch : line)[key] = Json(value);
    }
    line["batch"] = batch;
    lines_.emplace_back(sheet.index, line.dump());
    if (!ply_) return std::nullopt;
    return outputs_.stage(dir_ + plyName(sheet.index), [&](std::FILE* f) { return writePly(f, state); });
  }

  const CommonOptions& common_;
  const Plan& plan_;
  const InputScript& script_;
  std::string dir_;
  bool ply_;
  OutputSet& outputs_;
  Progress& progress_;
  uint64_t done_ = 0;
  std::vector<std::pair<uint64_t, std::string>> lines_;
};

} // namespace

int runSweep(const CommonOptions& common, const SweepOptions& o) {
  catchInterrupts(); // Ctrl-C or SIGTERM: the sweep stops between ticks, writes nothing and says so
  Plan plan;
  if (auto err = makePlan(common, o, plan)) return fail(*err);
  const std::vector<uint64_t> indices = shardIndices(plan);
  if (auto err = chooseBatch(plan, indices.size(), common.device)) return fail(*err);
  // Every sheet, and the script against it, is checked before anything runs. A fleet's sheets keep
  // their layout: the script's set events may change only keys that do not rebuild the sheet.
  std::string error;
  auto script = common.script.empty() ? InputScript{} : loadScript(common.script, error);
  if (!script) return fail(error);
  for (uint64_t index : indices) {
    SweepSheet sheet;
    if (auto err = makeSheet(plan, index, sheet)) return fail(*err);
    if (auto err = checkScript(*script, sheet.params, plan.backend, true))
      return fail(common.script + ": sheet " + std::to_string(index) + ": " + *err);
  }
  const auto script_hash = common.script.empty() ? std::nullopt : fileHash(common.script);
  const Json def = definition(plan, script_hash);
  if (!common.script.empty() && !script_hash) return fail("cannot read '" + common.script + "'");

  std::string dir;
  if (auto err = outputFolder(o.out, dir)) return fail(*err);
  if (auto err = otherShardIn(dir, def)) return fail(*err);
  OutputSet outputs;
  if (auto err = outputs.addInput(common.script)) return fail(*err);
  for (const char* name : {"sheets.jsonl", "sweep.json"})
    if (auto err = outputs.add(dir + name)) return fail(*err);
  if (o.ply)
    for (uint64_t index : indices)
      if (auto err = outputs.add(dir + plyName(index))) return fail(*err);

  const auto start = std::chrono::steady_clock::now();
  Progress progress("tender sweep", "sheet-tick", indices.size() * plan.ticks, 1.0);
  Runner runner(common, plan, *script, dir, o.ply, outputs, progress);
  auto err = runner.run(indices);
  progress.clear();
  if (err) return fail(*err);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  if (auto e = outputs.stage(dir + "sheets.jsonl", runner.lines())) return fail(*e);
  if (auto e = outputs.stage(dir + "sweep.json", def.dump(2) + "\n")) return fail(*e);
  if (auto e = otherShardIn(dir, def)) return fail(*e); // another shard may have finished there meanwhile
  if (interrupted()) return fail(interruptMessage() + "; nothing written");
  if (auto e = outputs.commit()) return fail(*e);
  const double rate = seconds > 0.0 ? double(indices.size() * plan.ticks) / seconds : 0.0;
  std::printf("tender sweep: %zu of %llu sheets (shard %llu/%llu) of %ux%u, %llu ticks on %s in %.1f s: %.0f "
              "sheet-ticks/s; %ssheets.jsonl\n",
              indices.size(), static_cast<unsigned long long>(plan.sheets), static_cast<unsigned long long>(plan.shard),
              static_cast<unsigned long long>(plan.shards), plan.base.cols, plan.base.rows,
              static_cast<unsigned long long>(plan.ticks), plan.backend.c_str(), seconds, rate, dir.c_str());
  return 0;
}

} // namespace tender
