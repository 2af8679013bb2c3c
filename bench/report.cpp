// tender-bench's tables and CSV (report.h).
#include "report.h"

#include <cstdio>
#include <sstream>

namespace tender::bench {

std::string humanBytes(uint64_t b) {
  char buf[32];
  if (b >= (1ull << 30))
    std::snprintf(buf, sizeof(buf), "%.2f GiB", double(b) / double(1ull << 30));
  else if (b >= (1ull << 20))
    std::snprintf(buf, sizeof(buf), "%.1f MiB", double(b) / double(1ull << 20));
  else
    std::snprintf(buf, sizeof(buf), "%.1f KiB", double(b) / 1024.0);
  return buf;
}

void printTable(const nlohmann::json& results) {
  std::printf("%-11s %-12s %9s %7s %10s %10s %14s %11s %7s %10s %10s %8s %6s\n", "size", "backend", "particles",
              "threads", "ms median", "ms p95", "part-substep/s", "dispatches", "phases", "memory", "MB/tick", "GB/s",
              "%peak");
  for (const auto& r : results) {
    if (r["status"] != "ok") {
      std::printf("%-11s %-12s %9llu  skipped: %s\n", r["size"].get<std::string>().c_str(),
                  r["backend"].get<std::string>().c_str(),
                  static_cast<unsigned long long>(r["particles"].get<uint64_t>()),
                  r["reason"].get<std::string>().c_str());
      continue;
    }
    const std::string pct = r.contains("peak_pct") ? std::to_string(std::lround(r["peak_pct"].get<double>())) : "-";
    std::printf("%-11s %-12s %9llu %7u %10.3f %10.3f %14.3g %11u %7u %10s %10.1f %8.2f %6s\n",
                r["size"].get<std::string>().c_str(), r["backend"].get<std::string>().c_str(),
                static_cast<unsigned long long>(r["particles"].get<uint64_t>()), r["threads"].get<uint32_t>(),
                r["ms_median"].get<double>(), r["ms_p95"].get<double>(), r["particle_substeps_per_s"].get<double>(),
                r["dispatches_per_tick"].get<uint32_t>(), r["barrier_phases_per_tick"].get<uint32_t>(),
                humanBytes(r["memory_bytes"].get<uint64_t>()).c_str(),
                double(r["bytes_per_tick"].get<uint64_t>()) / 1e6, r["achieved_gbps"].get<double>(), pct.c_str());
    if (!r["pass_ms"].empty()) {
      std::printf("%-11s   passes (ms, GB/s):", "");
      for (auto& [name, v] : r["pass_ms"].items()) {
        std::printf(" %s %.4f", name.c_str(), v.get<double>());
        if (r["pass_gbps"].contains(name)) std::printf(" (%.2f)", r["pass_gbps"][name].get<double>());
      }
      std::printf("\n");
    }
  }
}

void printBatchTable(const nlohmann::json& batches) {
  std::printf("\n%-11s %-8s %6s %14s %14s %16s %10s %11s %10s\n", "size", "backend", "batch", "ms/batch tick",
              "sheet-ticks/s", "part-substep/s", "x single", "dispatches", "memory");
  for (const auto& r : batches) {
    if (r["status"] != "ok") {
      std::printf("%-11s %-8s %6u  skipped: %s\n", r["size"].get<std::string>().c_str(),
                  r["backend"].get<std::string>().c_str(), r["batch"].get<uint32_t>(),
                  r["reason"].get<std::string>().c_str());
      continue;
    }
    const std::string speedup = r.contains("speedup_vs_single")
                                    ? std::to_string(r["speedup_vs_single"].get<double>()).substr(0, 5)
                                    : std::string("-");
    std::printf("%-11s %-8s %6u %14.3f %14.0f %16.3g %10s %11u %10s\n", r["size"].get<std::string>().c_str(),
                r["backend"].get<std::string>().c_str(), r["batch"].get<uint32_t>(), r["ms_median"].get<double>(),
                r["sheet_ticks_per_s"].get<double>(), r["particle_substeps_per_s"].get<double>(), speedup.c_str(),
                r["dispatches_per_tick"].get<uint32_t>(), humanBytes(r["memory_bytes"].get<uint64_t>()).c_str());
  }
}

std::string csvText(const nlohmann::json& results) {
  std::ostringstream f;
  f << "size,cols,rows,particles,backend,status,threads,ticks_measured,ms_median,ms_p95,ms_mean,ms_min,"
       "particle_substeps_per_s,dispatches_per_tick,memory_bytes,bytes_per_tick,achieved_gbps,peak_gbps,peak_pct,torn,"
       "state_hash,passes,pass_bytes,pass_gbps,barrier_phases_per_tick\n";
  for (const auto& r : results) {
    auto num = [&](const char* k) -> std::string { return r.contains(k) ? r[k].dump() : ""; };
    // name=value;name=value (pass_bytes: read + write)
    auto list = [&](const char* k) {
      std::string out;
      if (r.contains(k))
        for (auto& [name, v] : r[k].items())
          out += (out.empty() ? "" : ";") + name + "=" +
                 (v.is_object() ? std::to_string(v["read"].get<uint64_t>() + v["write"].get<uint64_t>()) : v.dump());
      return out;
    };
    f << r["size"].get<std::string>() << ',' << num("cols") << ',' << num("rows") << ',' << num("particles") << ','
      << r["backend"].get<std::string>() << ',' << r["status"].get<std::string>() << ',' << num("threads") << ','
      << num("ticks_measured") << ',' << num("ms_median") << ',' << num("ms_p95") << ',' << num("ms_mean") << ','
      << num("ms_min") << ',' << num("particle_substeps_per_s") << ',' << num("dispatches_per_tick") << ','
      << num("memory_bytes") << ',' << num("bytes_per_tick") << ',' << num("achieved_gbps") << ',' << num("peak_gbps")
      << ',' << num("peak_pct") << ',' << num("torn") << ','
      << (r.contains("state_hash") ? r["state_hash"].get<std::string>() : "") << ',' << list("pass_ms") << ','
      << list("pass_bytes") << ',' << list("pass_gbps") << ',' << num("barrier_phases_per_tick") << '\n';
  }
  return f.str();
}

} // namespace tender::bench
