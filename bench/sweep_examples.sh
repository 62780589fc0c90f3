#!/usr/bin/env bash
# isolink sweep on the example sweep files, one after another:
#   bash bench/sweep_examples.sh [ISOLINK_BINARY] [JOBS] [SWEEP...]
# (defaults: build/cli/isolink, JOBS = all cores, every netlists/examples/sweep_*.yaml). For each:
# points, pass / fail / error, wall time of the whole sweep (simulation, results.csv, summary.json,
# PNGs) and points per minute; the summed run time of the points over the wall time shows how well
# the cores were used. Set MPI_NP=N to run under `mpirun -np N` on this machine instead
# (ISOLINK_MPI builds; rank 0 only hands out points, so N = cores + 1).
# ENGINES="auto transient" runs each sweep once per `--engine` (back to back, one row each; the
# default is auto alone); the word `simulated` runs `--engine auto --simulate` (every point
# simulated by the LTI engine instead of superposed from its edge responses). The "fast path"
# column counts the points whose results.csv `path` is `edges` (the fast path, analysis/README.md).
# "CPU s / point" is the sweep process's user + system time (GNU time) over its points, start-up,
# summary and charts included; "points/min on 2 idle cores" is 120 / that: the rate two cores give
# when nothing else runs (on this shared machine the wall-clock rate depends on the others' load).
# Prints a Markdown table (for bench/README.md); the outputs stay in $OUT (default a temp folder).
set -euo pipefail
cd "$(dirname "$0")/.."
ISOLINK=${1:-build/cli/isolink}
JOBS=${2:-0}
shift $(($# < 2 ? $# : 2))
if (($# > 0)); then sweeps=("$@"); else sweeps=(netlists/examples/sweep_*.yaml); fi
OUT=${OUT:-$(mktemp -d)}
mkdir -p "$OUT"
jobs_arg=()
[ "$JOBS" != 0 ] && jobs_arg=(-j "$JOBS")
launch=()
if [ -n "${MPI_NP:-}" ]; then
  launch=(mpirun --allow-run-as-root --oversubscribe -np "$MPI_NP")
  export OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_plm=${OMPI_MCA_plm:-isolated}
fi

echo "| sweep | points | pass / fail / error | wall s | points/min | point s (mean) | cores busy | fast path | CPU s / point | points/min on 2 idle cores |"
echo "|---|---|---|---|---|---|---|---|---|---|"
read -r -a engines <<<"${ENGINES:-auto}"
for f in "${sweeps[@]}"; do
 for engine in "${engines[@]}"; do
  name=$(basename "$f" .yaml)
  ((${#engines[@]} > 1)) && name="$name ($engine)"
  dir="$OUT/$(basename "$f" .yaml)-$engine"
  rm -rf "$dir"
  s=$(date +%s%N)
  engine_args=(--engine "$engine")
  [ "$engine" = simulated ] && engine_args=(--engine auto --simulate)
  /usr/bin/time -f "%U %S" -o "$dir.cpu" "${launch[@]}" "$ISOLINK" sweep "$f" -o "$dir" -q \
    "${engine_args[@]}" "${jobs_arg[@]}" >/dev/null 2>&1 || true
  e=$(date +%s%N)
  cpu=$(tail -n 1 "$dir.cpu" | awk '{ print $1 + $2 }')
  awk -F, -v name="$name" -v ns=$((e - s)) -v cpu="$cpu" '
    NR == 1 { for (i = 1; i <= NF; i++) { if ($i == "verdict") v = i; if ($i == "seconds") t = i;
                                           if ($i == "path") p = i }; next }
    { n++; c[$v]++; sum += $t; if (p && $p == "edges") fast++ }
    END {
      wall = ns / 1e9
      printf "| %s | %d | %d / %d / %d | %.1f | %.1f | %.2f | %.2f | %d | %.3f | %.0f |\n", name, n,
             c["pass"], c["fail"], c["error"], wall, n / wall * 60, sum / n, sum / wall, fast,
             cpu / n, 2 * 60 * n / cpu
    }' "$dir/results.csv"
 done
done
echo
echo "outputs: $OUT"
