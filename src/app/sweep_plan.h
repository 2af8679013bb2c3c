#pragma once
/// A sweep's plan, shared by `tender sweep` and `tender sweep-merge`: its base parameters, its axes
/// (--vary), how each sheet's values are chosen (a grid, or samples by seed), its shards, and its
/// definition (sweep.json), from which a merge rebuilds the plan to check every line it joins.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.h"

namespace tender::sweep {

using Json = nlohmann::ordered_json;

/// Most sheets of one sweep (its lines are held in memory until they are written).
constexpr uint64_t kMaxSweepSheets = 1000000;
/// Sheets per batch when --batch is not given (fewer when memory is short).
constexpr uint64_t kDefaultCpuBatch = 64;
constexpr uint64_t kDefaultGpuBatch = 1024;
/// Largest sweep.json, and the most bytes a line of sheets.jsonl may take (its stats are ~1 KB).
constexpr uint64_t kMaxDefinitionBytes = 16u << 20;
constexpr uint64_t kMaxLineBytes = 64u << 10;

/// One --vary: a key and its values (a list, or a range a:b:n spelled out), or for --samples a
/// list or a range a:b to draw from.
struct Axis {
  std::string key;
  bool numeric = false, whole = false;
  std::vector<std::string> values; ///< each spelled as `--set` takes it; empty: a sampled range
  double lo = 0.0, hi = 0.0;       ///< the sampled range a:b
};

/// A whole sweep: its base parameters, its axes and how the sheets' values are chosen.
struct Plan {
  SimParams base;
  std::string backend;
  std::vector<std::string> vary; ///< the --vary arguments, as given
  std::vector<Axis> axes;
  uint64_t samples = 0; ///< 0: the grid of every combination
  uint64_t seed = 0;
  uint64_t sheets = 0;
  uint64_t ticks = 0;
  uint64_t shard = 0, shards = 1;
  uint64_t batch = 0; ///< sheets per batch
};

/// One sheet of the sweep: its parameters and its values as JSON (numbers, true/false, names).
struct SweepSheet {
  uint64_t index = 0;
  SimParams params;
  Json values = Json::object();
};

/// Parses the command line's numbers, shard and axes into a plan.
std::optional<std::string> makePlan(const CommonOptions& common, const SweepOptions& o, Plan& plan);
/// The plan a sweep's definition (sweep.json) describes; "not a sweep's definition (<why>)" when
/// it describes none.
std::optional<std::string> planOfDefinition(const Json& definition, Plan& plan);
/// Sheet `index` of the plan: its parameters and values, checked as `--set` checks them.
std::optional<std::string> sheetOf(const Plan& plan, uint64_t index, SweepSheet& out);
/// As sheetOf(), and the sheet must fit this machine's memory on the plan's backend.
std::optional<std::string> makeSheet(const Plan& plan, uint64_t index, SweepSheet& out);
/// The indices of this shard's sheets: those equal to the shard modulo the shard count.
std::vector<uint64_t> shardIndices(const Plan& plan);
/// How many sheets shard `shard` of `shards` holds of `sheets`.
uint64_t shardSize(uint64_t sheets, uint64_t shard, uint64_t shards);
/// Picks the sheets per batch: --batch, or the backend's default, within the memory available (on
/// the GPU, also the device's).
std::optional<std::string> chooseBatch(Plan& plan, uint64_t shard_sheets, int device);
/// FNV-1a 64 of a file's bytes, as 16 hex digits; nullopt when it cannot be read.
std::optional<std::string> fileHash(const std::string& path);
/// The sweep's definition (sweep.json): everything that decides its sheets' lines, and the shard.
Json definition(const Plan& plan, const std::optional<std::string>& script_hash);
/// The first key apart from "shard" in which two definitions differ; nullopt when they define one
/// sweep.
std::optional<std::string> definitionMismatch(const Json& a, const Json& b);
/// The name of a sheet's PLY file, sheet_NNNNNN.ply.
std::string plyName(uint64_t index);
/// The folder of --out with a trailing '/', created when missing.
std::optional<std::string> outputFolder(const std::string& out, std::string& dir);

} // namespace tender::sweep
