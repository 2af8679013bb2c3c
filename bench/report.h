#pragma once
/// tender-bench's tables on standard output and its CSV.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace tender::bench {

/// "1.5 MiB": a byte count for people.
std::string humanBytes(uint64_t b);
/// The table of the single-sheet cases.
void printTable(const nlohmann::json& results);
/// The table of the fleets (--batch).
void printBatchTable(const nlohmann::json& batches);
/// The single-sheet cases as CSV.
std::string csvText(const nlohmann::json& results);

} // namespace tender::bench
