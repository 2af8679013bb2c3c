#!/usr/bin/env bash
# Smoke test of tender-bench: two tiny sizes on every built backend; checks the JSON's and the
# CSV's shape (never the timings) and that bad input exits 2 with one line.
set -u
B=${TENDER_BENCH:?set TENDER_BENCH to the tender-bench binary}
backends=${TENDER_BENCH_BACKENDS:-cpu}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0

# The tender preset as the seeds' cloth, its contact off: a CPU device takes seconds to build
# contact's kernels (contact's cost: bench/README.md)
seeds=(--set contact_factor=0)
if ! "$B" --sizes 8x12,12x16 --backends "$backends" "${seeds[@]}" --ticks 3 --warmup 1 --json "$tmp/b.json" --csv "$tmp/b.csv" \
    >"$tmp/out" 2>"$tmp/err"; then
  echo "FAIL: bench run exited $?"; cat "$tmp/out" "$tmp/err"; failures=$((failures + 1))
else
  cat "$tmp/out"
  python3 - "$tmp/b.json" "$tmp/b.csv" "$backends" <<'PY' || failures=$((failures + 1))
import csv, json, sys
j = json.load(open(sys.argv[1]))
backends = sys.argv[3].split(",")
for k in ["tool", "version", "machine", "preset", "ticks", "warmup", "sets", "peak_bandwidth", "results"]:
    assert k in j, k
# The measured copy bandwidths (the device's may be skipped, with a reason).
peaks = j["peak_bandwidth"]
for key in ["cpu"] + (["gpu"] if any(b != "cpu" for b in backends) else []):
    p = peaks[key]
    if "skipped" in p:
        assert key == "gpu", p; print("gpu peak skipped:", p["skipped"]); continue
    assert p["gbps"] > 0 and p["buffer_bytes"] > 0 and p["repetitions"] > 0 and p["method"], p
assert j["tool"] == "tender-bench" and j["ticks"] == 3 and j["warmup"] == 1, j
# The cost of an empty dispatch and barrier, measured on the device when a GPU backend runs.
assert "dispatch_cost" in j, j.keys()
if any(b != "cpu" for b in backends):
    d = j["dispatch_cost"]["gpu"]
    if "skipped" in d:
        print("dispatch cost skipped:", d["skipped"])
    else:
        assert d["dispatch_us"] > 0 and d["chain"] > 0 and len(d["samples_us"]) == d["repetitions"] > 0, d
        assert d["device"] and d["method"], d
else:
    assert j["dispatch_cost"] == {}, j["dispatch_cost"]
assert "cpu_model" in j["machine"] and "cores" in j["machine"], j["machine"]
rs = j["results"]
assert len(rs) == 2 * len(backends), len(rs)
seen = set()
for r in rs:
    for k in ["size", "cols", "rows", "particles", "backend", "status"]:
        assert k in r, (k, r)
    seen.add((r["size"], r["backend"]))
    if r["backend"].startswith("gpu") and r["status"] == "skipped":
        print("gpu skipped:", r.get("reason")); continue
    assert r["status"] == "ok", r
    for k in ["ms_median", "ms_p95", "ms_mean", "ms_min", "ticks_measured", "particle_substeps_per_s",
              "dispatches_per_tick", "barrier_phases_per_tick", "memory_bytes", "pass_ms", "threads", "spacing",
              "cell_size", "torn", "state_hash"]:
        assert k in r, (k, r)
    # Barrier phases: the fused tick's alone (the per-colour passes' and the CPU's are dispatches)
    assert (r["barrier_phases_per_tick"] > 0) == (r["pass_ms"].get("fused_tick", 0) > 0), r
    assert r["particles"] == r["cols"] * r["rows"] and r["ticks_measured"] == 3, r
    assert 0 < r["ms_min"] <= r["ms_median"] <= r["ms_p95"], r
    assert r["memory_bytes"] > r["particles"] * 32 and r["dispatches_per_tick"] > 0, r
    assert isinstance(r["pass_ms"], dict), r
    # The traffic model: every pass, read and write, adding up to bytes_per_tick.
    passes = {"integrate", "project", "hash", "collide", "floor", "tear"}
    pb = r["pass_bytes"]
    assert set(pb) == passes and all(v["read"] >= 0 and v["write"] >= 0 for v in pb.values()), pb
    assert r["bytes_per_tick"] == sum(v["read"] + v["write"] for v in pb.values()) > r["particles"] * 32, r
    assert pb["project"]["read"] > 0 and r["achieved_gbps"] > 0, r
    assert set(r["pass_gbps"]) <= passes and all(v > 0 for v in r["pass_gbps"].values()), r
    peak = peaks.get("gpu" if r["backend"].startswith("gpu") else "cpu", {})
    if "gbps" in peak:
        assert r["peak_gbps"] == peak["gbps"] and r["peak_pct"] > 0, r
    if r["backend"] == "gpu":
        assert len(r["pass_ms"]) > 0, r
assert seen == {(s, b) for s in ["8x12", "12x16"] for b in backends}, seen
rows = list(csv.DictReader(open(sys.argv[2])))
assert len(rows) == len(rs) and "ms_median" in rows[0] and "particles" in rows[0], rows[:1]
assert int(rows[0]["bytes_per_tick"]) > 0 and "peak_pct" in rows[0] and "pass_bytes" in rows[0], rows[:1]
print("ok: JSON and CSV shape,", len(rs), "results")
PY
fi

# --no-peak skips the bandwidth measurement: no peak, no percent, the traffic model still there.
if "$B" --sizes 8x12 --backends cpu --ticks 3 --warmup 0 --no-peak --json "$tmp/n.json" >/dev/null 2>&1 &&
    python3 -c 'import json, sys; j = json.load(open(sys.argv[1])); r = j["results"][0]
assert j["peak_bandwidth"] == {} and "peak_pct" not in r and r["bytes_per_tick"] > 0' "$tmp/n.json"; then
  echo "ok: --no-peak"
else
  echo "FAIL: --no-peak"; failures=$((failures + 1))
fi

# On the device, --no-peak still measures the dispatch cost (it takes a fraction of a second).
if [ "$backends" != cpu ]; then
  if "$B" --sizes 8x12 --backends gpu "${seeds[@]}" --ticks 1 --warmup 0 --no-peak --json "$tmp/d.json" >/dev/null 2>"$tmp/err" &&
      grep -q "^dispatch gpu: " "$tmp/err" &&
      python3 -c 'import json, sys; j = json.load(open(sys.argv[1])); d = j["dispatch_cost"]["gpu"]
assert j["peak_bandwidth"] == {} and ("skipped" in d or d["dispatch_us"] > 0), d' "$tmp/d.json"; then
    echo "ok: --no-peak on the device: $(grep '^dispatch gpu' "$tmp/err")"
  else
    echo "FAIL: --no-peak on the device: no dispatch cost"; cat "$tmp/err"; failures=$((failures + 1))
  fi
fi

# The plot script turns the JSON into a PNG (when gnuplot is installed).
plot=$(dirname "$0")/../tools/plot-bench
if command -v gnuplot >/dev/null && [ -f "$tmp/b.json" ]; then
  if "$plot" -o "$tmp/b.png" "$tmp/b.json" >/dev/null && [ -s "$tmp/b.png" ]; then
    echo "ok: plot-bench wrote a PNG"
  else
    echo "FAIL: plot-bench"; failures=$((failures + 1))
  fi
fi

# Fleets: --batch runs batches of sheets per size and backend; the fleet plot draws them.
if "$B" --sizes 8x12 --backends "$backends" "${seeds[@]}" --batch 1,3 --ticks 2 --warmup 0 --no-peak --json "$tmp/f.json" \
  >"$tmp/out" 2>&1 && python3 - "$tmp/f.json" "$backends" <<'PY'; then
import json, sys
j = json.load(open(sys.argv[1]))
b = j["batches"]
assert [(r["backend"], r["batch"]) for r in b] == [(k, n) for k in sys.argv[2].split(",") for n in (1, 3)], b
for r in b:
    assert r["status"] == "ok", r
    assert abs(r["sheet_ticks_per_s"] - 1000.0 * r["batch"] / r["ms_median"]) < 1e-6 * r["sheet_ticks_per_s"], r
    assert r["speedup_vs_single"] > 0 and r["dispatches_per_tick"] >= 1, r
PY
  echo "ok: --batch 1,3 ran a fleet per backend"
else
  echo "FAIL: --batch"; cat "$tmp/out"; failures=$((failures + 1))
fi
if command -v gnuplot >/dev/null && [ -f "$tmp/f.json" ]; then
  if "$(dirname "$0")/../tools/plot-fleet" -o "$tmp/f.png" "$tmp/f.json" >/dev/null && [ -s "$tmp/f.png" ]; then
    echo "ok: plot-fleet wrote a PNG"
  else
    echo "FAIL: plot-fleet"; failures=$((failures + 1))
  fi
fi

expect_bad() { # args...: must exit 2 with one stderr line
  "$B" "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$? lines
  lines=$(wc -l <"$tmp/err")
  if [ "$rc" -ne 2 ] || [ "$lines" -ne 1 ]; then
    echo "FAIL: tender-bench $* -> exit $rc, $lines stderr lines:"; cat "$tmp/err"; failures=$((failures + 1))
  else
    echo "ok: tender-bench $* -> $(cat "$tmp/err")"
  fi
}
expect_bad --sizes 32by48
expect_bad --sizes 0x10
expect_bad --sizes ""
expect_bad --backends quantum
expect_bad --preset nope
expect_bad --set nope=1
expect_bad --set damping=2
expect_bad --ticks 0
expect_bad --sizes 8x12 --batch 0
expect_bad --sizes 8x12 --batch 1,x
expect_bad --bogus
expect_bad --sizes 8x12 --max-seconds nan
expect_bad --sizes 8x12 --max-cpu-particles -1
expect_bad --sizes 4294967328x48
expect_bad --sizes 8x12 --backends cpu --json /nonexistent/dir/b.json
# A write error after the sweep (progress lines come first on stderr) ends with the error, exit 2.
"$B" --sizes 8x12 --backends cpu --csv /dev/full --no-peak --ticks 1 --warmup 0 >/dev/null 2>"$tmp/err"
rc=$?
[ "$rc" -eq 2 ] && tail -1 "$tmp/err" | grep -q "^tender-bench: error: cannot write '/dev/full'" &&
  echo "ok: --csv /dev/full -> $(tail -1 "$tmp/err")" || { echo "FAIL: --csv /dev/full -> exit $rc"; failures=$((failures + 1)); }
if [ "$backends" != cpu ]; then
  expect_bad --sizes 8x12 --backends gpu --device 99
  VK_DRIVER_FILES=/nonexistent.json expect_bad --sizes 8x12 --backends gpu
fi
"$B" --help >/dev/null && "$B" --version | grep -q '^tender-bench ' || { echo "FAIL: --help/--version"; failures=$((failures + 1)); }
echo "$failures failed"
[ "$failures" -eq 0 ]
