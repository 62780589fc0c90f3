#!/usr/bin/env bash
# isolink stress on every example link spec and pack, one after another:
#   bash bench/stress_examples.sh [ISOLINK_BINARY] [JOBS] [SPEC...]
# (defaults: build/cli/isolink, JOBS = 2, every netlists/examples/*.yaml link spec, the
# noise_ti ones and the pack). For each: scenarios, how many break something, the engines they
# ran on, the slowest scenario (its report.json `seconds`), wall time and peak memory of the
# whole command (GNU time: report.md/json/html and stress.png included). The issue's budget is
# the default set on a 15 m link within 2 minutes on 2 cores. Prints a Markdown table (for
# bench/README.md); the reports stay in $OUT (default a temp folder).
set -euo pipefail
cd "$(dirname "$0")/.."
ISOLINK=${1:-build/cli/isolink}
JOBS=${2:-2}
shift $(($# < 2 ? $# : 2))
if (($# > 0)); then
  specs=("$@")
else
  specs=()
  for f in netlists/examples/*.yaml netlists/examples/noise_ti/*.yaml; do
    case "$(basename "$f")" in sweep_* | startup_*) continue ;; esac
    specs+=("$f")
  done
  specs+=(netlists/examples/pack/pack_16.yaml)
fi
OUT=${OUT:-$(mktemp -d)}
mkdir -p "$OUT"
echo "| spec | scenarios | break | engines | slowest scenario | wall | peak memory |"
echo "|---|---|---|---|---|---|---|"
for spec in "${specs[@]}"; do
  name=$(basename "$spec" .yaml)
  rc=0
  /usr/bin/time -f "%e %M" -o "$OUT/$name.time" "$ISOLINK" stress "$spec" -j "$JOBS" -q --json \
    -o "$OUT/$name" >"$OUT/$name.json" 2>"$OUT/$name.err" || rc=$?
  if ((rc > 1)); then
    echo "| $name | error (exit $rc): $(head -c 200 "$OUT/$name.err" | tr '\n|' ' /') | | | | | |"
    continue
  fi
  read -r wall kb < <(tail -n 1 "$OUT/$name.time")
  python3 - "$OUT/$name.json" "$name" "$wall" "$kb" <<'EOF'
import json, sys
path, name, wall, kb = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
d = json.load(open(path))
scen = d.get("scenarios", [])
if "faults" in d:  # a pack: each hop's wire faults, one simulation per distinct hop and fault
    scen = [f["scenario"] for f in d["faults"] if f.get("scenario")]
    name += f" ({d['simulations']} simulations)"
engines = sorted({s.get("engine", "?").split(" ")[0] for s in scen})
broken = sum(1 for s in scen if s.get("first_broken"))
slow = max(scen, key=lambda s: s.get("seconds", 0)) if scen else None
slowest = f"{slow['seconds']:.1f} s ({slow['id']})" if slow else "-"
print(f"| {name} | {len(scen)} | {broken} | {', '.join(engines)} | {slowest} | {wall:.1f} s "
      f"| {kb / 1024:.0f} MB |")
EOF
done
