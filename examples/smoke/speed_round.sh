#!/usr/bin/env bash
# The smoke solver's speed figures of the README in one run, in this order: Plume against
# Mantaflow in one Blender (compare_mantaflow.py: matched numerics, defaults against defaults,
# both adaptive domains), then the 256³ rows (each in its own process, for its peak memory), the
# adaptive-domain benchmark at 64³ and the torch. Run it on an otherwise idle machine; it prints
# the load average before and after. Needs the add-on installed and the build in build/.
#   bash examples/smoke/speed_round.sh [BLENDER]      (about 15 minutes on 2 cores)
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
BLENDER="${1:-blender}"
BENCH="$ROOT/build/native"
compare() {
  echo "== compare_mantaflow.py $*"
  "$BLENDER" -b --factory-startup --python "$ROOT/examples/smoke/compare_mantaflow.py" -- "$@" \
    2>&1 | grep -E '^(compare_mantaflow|mantaflow|plume|ratio)' \
    | sed -E 's/; cache [^;]*(max density)/; \1/; s/, incl\. state\.bin checkpoint [0-9.]+ MiB//'
}
echo "== load before: $(cut -d' ' -f1-3 /proc/loadavg)"
compare 64 20
compare 128 10
compare --defaults 64 20
compare --defaults 128 20
compare --adaptive 128 60
for row in 'BM_StepComparable/256' 'BM_Step/256'; do
  echo "== plume_bench $row (own process: peak_rss_MB is this row's)"
  "$BENCH/plume_bench" --benchmark_filter="^$row/" --benchmark_min_time=0.1 2>&1 | grep -E "^BM_"
done
echo "== plume_bench_adaptive BM_Bake60/64"
"$BENCH/plume_bench_adaptive" --benchmark_filter='BM_Bake60/64' 2>&1 | grep -E "^BM_|ratio"
echo "== plume_bench_flames_shape BM_TorchFrame"
"$BENCH/plume_bench_flames_shape" --benchmark_filter='BM_TorchFrame' --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=true 2>&1 | grep -E "^BM_"
echo "== load after: $(cut -d' ' -f1-3 /proc/loadavg)"
