#!/usr/bin/env bash
# Scaling of `isolink run` with the length of the traffic (issue 45): the default link spec (2 m,
# capacitor isolation) with N repeated stack-write commands, down direction, worst case included,
# for each N given. Prints one Markdown row per N: wall time, peak memory (max RSS) and the size of
# every bundle file over 1 MB.
#
#   bash bench/long_traffic.sh [build/cli/isolink] [N ...]        # default N: 1 10 100 1000 2000
#   EXTRA="--wave rows" bash bench/long_traffic.sh build/cli/isolink 100
#   NGSPICE_FRAMES="1 10" bash bench/long_traffic.sh build/cli/isolink 1 10 100
# For each N in NGSPICE_FRAMES (default: none) ngspice is timed in the same run on the spec's
# netlist (`isolink export-spice`, the down direction, ngspice's defaults plus rshunt=1e12 as
# bench/sim_vs_ngspice.sh runs it), stopped after NGSPICE_TIMEOUT s (default 900; "> T" then).
set -euo pipefail
# shellcheck source=bench/frames_spec.sh
source "$(dirname "$0")/frames_spec.sh"
exe=${1:-build/cli/isolink}
shift || true
counts=("$@")
[ ${#counts[@]} -eq 0 ] && counts=(1 10 100 1000 2000)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
ngspice_frames=" ${NGSPICE_FRAMES:-} "
ng_timeout=${NGSPICE_TIMEOUT:-900}
# ngspice's wall time on the spec's netlist, in s ("-" when N is not asked for, "> T" past T).
time_ngspice() {
  [[ $ngspice_frames == *" $1 "* ]] || { echo "-"; return; }
  "$exe" export-spice "$2" --direction down -o "$work/deck.cir" >/dev/null 2>&1
  sed -i '/^\.[eE][nN][dD]\s*$/d' "$work/deck.cir"
  # A .control block runs the .tran in batch mode (without one, or a .print, ngspice runs nothing).
  printf '.options rshunt=1e12\n.control\nrun\n.endc\n.end\n' >>"$work/deck.cir"
  local s e rc=0
  s=$(date +%s%N)
  timeout "$ng_timeout" ngspice -b "$work/deck.cir" >"$work/ngspice.log" 2>&1 || rc=$?
  e=$(date +%s%N)
  if ((rc == 124)); then
    echo "> $ng_timeout"
  elif ! grep -q "No. of Data Rows" "$work/ngspice.log"; then  # its exit status is 1 even then
    echo "failed"
  else
    awk -v ns=$((e - s)) 'BEGIN{printf "%.1f", ns / 1e9}'
  fi
}
echo "<!-- $(date -u +%Y-%m-%d), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg) -->"
echo "| frames | traffic (ms) | isolink run (s) | engine (s) | engine rows | max RSS (MB) | wave.csv (MB) | wave.csv rows, tolerance | report.html (MB) | report.json (MB) | exit | ngspice (s) |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for n in "${counts[@]}"; do
  spec="$work/cap_$n.yaml"
  write_frames_spec "$n" "$spec"
  out="$work/out_$n"
  set +e
  /usr/bin/time -f '%e %M' -o "$work/time" "$exe" run "$spec" -o "$out" -q ${EXTRA:-} 2>"$work/err"
  rc=$?
  set -e
  read -r secs kb < <(tail -n 1 "$work/time")
  size() { [ -f "$out/$1" ] && awk -v b="$(stat -c %s "$out/$1")" 'BEGIN{printf "%.1f", b / 1e6}' || echo -; }
  facts=$(python3 - "$out/report.json" <<'PY' 2>/dev/null || echo "- | - | - | -"
import json, sys
j = json.load(open(sys.argv[1]))
d = j["directions"][0]
c, s, w = d.get("check") or {}, d["solver"], j.get("wave_csv", {})
span = (c.get("t_end_s", 0) - c.get("t_begin_s", 0)) * 1e3
tol = w.get("tolerance_v", 0)
print(f"{span:.2f} | {s['seconds']:.1f} | {s.get('rows', '-')} | "
      f"{w.get('rows', '-')}, {tol * 1e3:g} mV" if tol else f"{span:.2f} | {s['seconds']:.1f} | {s.get('rows', '-')} | {w.get('rows', '-')}")
PY
)
  IFS='|' read -r traffic engine rows wrows <<<"$facts"
  echo "| $n |$traffic| $secs |$engine|$rows| $((kb / 1024)) | $(size wave.csv) |$wrows| $(size report.html) | $(size report.json) | $rc | $(time_ngspice "$n" "$spec") |"
done
