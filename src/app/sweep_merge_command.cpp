// `tender sweep-merge`: joins the shards of one sweep (`tender sweep --shard i/n`) into the whole
// sweep's files. Every shard's definition must describe the same sweep, and every line must be a
// sheet of that sweep and of its folder's shard, with the values the sweep gives that sheet.
#include <algorithm>
#include <cstdio>

#include "commands.h"
#include "core/input_file.h"
#include "core/output.h"
#include "sweep_plan.h"

namespace tender {
namespace {

using namespace sweep;

/// One shard read back: its definition and its lines by index.
struct ShardFiles {
  std::string dir;
  Json definition;
  std::vector<std::pair<uint64_t, std::string>> lines;
};

/// True when `text` is a state hash: 16 lowercase hex digits.
bool isStateHash(const std::string& text) {
  return text.size() == 16 && text.find_first_not_of("0123456789abcdef") == std::string::npos;
}

/// Why a line of a shard's sheets.jsonl is not a sheet of its sweep and shard; nullopt when it is.
std::optional<std::string> lineMismatch(const Plan& plan, const Json& j) {
  if (!j.is_object() || !j.contains("index") || !j["index"].is_number_unsigned() ||
      j["index"].get<uint64_t>() >= plan.sheets)
    return "not a sheet of this sweep (an object with an index below " + std::to_string(plan.sheets) + ")";
  const uint64_t index = j["index"].get<uint64_t>();
  if (index % plan.shards != plan.shard)
    return "sheet " + std::to_string(index) + " is not in shard " + std::to_string(plan.shard) + "/" +
           std::to_string(plan.shards) + " of the folder's sweep.json";
  SweepSheet sheet;
  if (auto err = sheetOf(plan, index, sheet)) return err;
  if (!j.contains("values") || j["values"] != sheet.values)
    return "sheet " + std::to_string(index) + ": its values are not the sweep's " + sheet.values.dump();
  if (!j.contains("state_hash") || !j["state_hash"].is_string() || !isStateHash(j["state_hash"].get<std::string>()))
    return "sheet " + std::to_string(index) + ": state_hash is not 16 hex digits";
  if (!j.contains("ticks") || !j["ticks"].is_number_unsigned() || j["ticks"].get<uint64_t>() != plan.ticks)
    return "sheet " + std::to_string(index) + ": ticks is not the sweep's " + std::to_string(plan.ticks);
  if (!j.contains("preset") || j["preset"] != plan.base.preset)
    return "sheet " + std::to_string(index) + ": preset is not the sweep's '" + plan.base.preset + "'";
  return std::nullopt;
}

/// Reads a shard's folder: its definition, and every line checked against it.
std::optional<std::string> loadShard(const std::string& folder, ShardFiles& out) {
  out.dir = folder.back() == '/' ? folder : folder + "/";
  std::string text;
  const std::string def_path = out.dir + "sweep.json", lines_path = out.dir + "sheets.jsonl";
  if (auto why = readInputFile(def_path, kMaxDefinitionBytes, text)) return "cannot read '" + def_path + "': " + *why;
  out.definition = Json::parse(text, nullptr, false);
  Plan plan;
  if (auto err = planOfDefinition(out.definition, plan)) return def_path + ": " + *err;
  // At most a line's worth of bytes per sheet of the shard.
  const uint64_t limit = std::max<uint64_t>(1, shardSize(plan.sheets, plan.shard, plan.shards)) * kMaxLineBytes;
  if (auto why = readInputFile(lines_path, limit, text)) return "cannot read '" + lines_path + "': " + *why;
  uint64_t n = 0;
  for (size_t at = 0; at < text.size();) {
    size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(at, end - at);
    at = end + 1;
    ++n;
    if (line.empty()) continue;
    const Json j = Json::parse(line, nullptr, false);
    if (auto why = lineMismatch(plan, j)) return lines_path + ": line " + std::to_string(n) + ": " + *why;
    out.lines.emplace_back(j["index"].get<uint64_t>(), line);
  }
  return std::nullopt;
}

/// Why two shards' definitions are not of one sweep (the first field apart from the shard that
/// differs); nullopt when they are.
std::optional<std::string> sweepMismatch(const ShardFiles& a, const ShardFiles& b) {
  for (auto& [key, value] : a.definition.items())
    if (key != "shard" && (!b.definition.contains(key) || b.definition[key] != value))
      return b.dir + " is a shard of another sweep than " + a.dir + " (" + key + " differs)";
  for (auto& [key, value] : b.definition.items())
    if (!a.definition.contains(key))
      return b.dir + " is a shard of another sweep than " + a.dir + " (" + key + " differs)";
  return std::nullopt;
}

/// "3, 7, 12 and 40 more": the first few indices of a list.
std::string someIndices(const std::vector<uint64_t>& v) {
  std::string s;
  for (size_t k = 0; k < std::min<size_t>(v.size(), 10); ++k) s += (k ? ", " : "") + std::to_string(v[k]);
  if (v.size() > 10) s += " and " + std::to_string(v.size() - 10) + " more";
  return s;
}

} // namespace

int runSweepMerge(const SweepMergeOptions& o) {
  if (o.dirs.empty()) return fail("sweep-merge: name the shards' folders");
  std::vector<ShardFiles> shards(o.dirs.size());
  for (size_t k = 0; k < o.dirs.size(); ++k) {
    if (auto err = loadShard(o.dirs[k], shards[k])) return fail(*err);
    if (auto err = sweepMismatch(shards[0], shards[k])) return fail(*err);
  }
  // Every sheet exactly once.
  const uint64_t sheets = shards[0].definition["sheets"].get<uint64_t>();
  std::vector<const std::string*> line_of(sheets, nullptr);
  std::vector<std::string> from(sheets);
  for (const ShardFiles& shard : shards)
    for (auto& [index, line] : shard.lines) {
      if (line_of[index])
        return fail("sheet " + std::to_string(index) + " is doubled (in " + from[index] + " and " + shard.dir + ")");
      line_of[index] = &line;
      from[index] = shard.dir;
    }
  std::vector<uint64_t> missing;
  for (uint64_t i = 0; i < sheets; ++i)
    if (!line_of[i]) missing.push_back(i);
  if (!missing.empty())
    return fail(std::to_string(missing.size()) + " of " + std::to_string(sheets) +
                " sheets are missing: " + someIndices(missing));

  std::string dir;
  if (auto err = outputFolder(o.out, dir)) return fail(*err);
  OutputSet outputs;
  for (const char* name : {"sheets.jsonl", "sweep.json"})
    if (auto err = outputs.add(dir + name)) return fail(*err);
  std::string text;
  for (const std::string* line : line_of) text += *line + "\n";
  Json def = shards[0].definition;
  def["shard"] = "0/1";
  if (auto err = outputs.stage(dir + "sheets.jsonl", text)) return fail(*err);
  if (auto err = outputs.stage(dir + "sweep.json", def.dump(2) + "\n")) return fail(*err);
  if (auto err = outputs.commit()) return fail(*err);
  std::printf("tender sweep-merge: %llu sheets from %zu shards; %ssheets.jsonl\n",
              static_cast<unsigned long long>(sheets), shards.size(), dir.c_str());
  return 0;
}

} // namespace tender
