#!/usr/bin/env bash
# The port model (isolink's default engine for circuits with diodes) against the full-circuit
# Newton transient and ngspice, all in one run:
#   bash bench/nonlinear_vs_ngspice.sh [ISOLINK_BINARY] [N] [LENGTH_M...]
# (defaults: build/cli/isolink, N=3, lengths 2 3 6 12 m.) Each length is the cap-isolated hop of
# tests/cli/data/nonlinear/link_clamp_cm_step.cir (TVS at both connectors, the receiver pins'
# clamps, the transmitter's ground stepping 60 V in 1 us during traffic) with its cable as
# 2 x LENGTH LC sections per line (0.5 m each), written by this script; plus the four circuits
# of tests/cli/data/nonlinear/. For each, wall time best of N, process start included:
#   - `isolink sim` at its defaults (auto: the port model);
#   - `isolink sim --engine transient` at its defaults (self-checked: rerun tighter until two
#     runs agree within 5 mV);
#   - ngspice at its defaults (`ngspice -b`, wrdata);
# and the deviation of each from the reference, isolink --engine transient --reltol 1e-6
# (converged: tests/cli/nonlinear_compare_test.cpp), max over the reference's time points.
set -euo pipefail
cd "$(dirname "$0")/.."
ISOLINK=${1:-build/cli/isolink}
N=${2:-3}
shift $(($# < 2 ? $# : 2))
lengths=("$@")
((${#lengths[@]})) || lengths=(2 3 6 12)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

link() {  # link LENGTH FILE: the clamp hop with 2 x LENGTH sections per line
  python3 - "$1" "$2" <<'PY'
import sys
length, out = float(sys.argv[1]), sys.argv[2]
src = open("tests/cli/data/nonlinear/link_clamp_cm_step.cir").read().splitlines()
head, tail, skip = [], [], False
for line in src:
    if line.startswith("* cable"):
        skip = True
        continue
    if line.startswith("* RX board"):
        skip = False
    if skip:
        continue
    (tail if tail or line.startswith("* RX board") else head).append(line)
n = max(1, round(2 * length))
cable = [f"* cable: {n} sections of 0.5 m per line"]
prev = ("c1p", "c1n")
for k in range(1, n + 1):
    cur = ("c2p", "c2n") if k == n else (f"m{k}p", f"m{k}n")
    cable += [f"L{k}P {prev[0]} {cur[0]} 0.35u", f"L{k}N {prev[1]} {cur[1]} 0.35u",
              f"C{k}PG {cur[0]} 0 25p", f"C{k}NG {cur[1]} 0 25p", f"C{k}PN {cur[0]} {cur[1]} 12p"]
    prev = cur
head[0] = f"Clamp hop, {length:g} m cable (bench/nonlinear_vs_ngspice.sh)"
open(out, "w").write("\n".join(head + cable + tail) + "\n")
PY
}

best() {  # best wall time in ms of N runs of "$@"
  local b=999999999 s e ms
  for _ in $(seq "$N"); do
    s=$(date +%s%N)
    "$@" >/dev/null 2>&1 || true
    e=$(date +%s%N)
    ms=$(((e - s) / 1000000))
    ((ms < b)) && b=$ms
  done
  echo "$b"
}

ngdeck() {  # netlist deck data probe
  sed '/^\.[eE][nN][dD]\s*$/d' "$1" >"$2"
  printf '.control\nset wr_singlescale\noption numdgt=12\nrun\nwrdata %s %s\n.endc\n.end\n' \
    "$3" "$4" >>"$2"
}

maxdev() {  # max |test - ref| in mV over ref's time points, test interpolated linearly
  awk '
    function num(s) { return s ~ /^[-+0-9.eE]+$/ }
    { sub(/^[ \t]+/, ""); n = split($0, f, /[ ,\t]+/); if (n < 2 || !num(f[1]) || !num(f[2])) next }
    FNR == NR { if (m > 0 && f[1] + 0 <= t[m - 1]) next; t[m] = f[1] + 0; v[m] = f[2] + 0; m++; next }
    { x = f[1] + 0; if (m < 2 || x < t[0] || x > t[m - 1]) next
      while (j < m - 2 && t[j + 1] < x) j++
      y = v[j] + (v[j + 1] - v[j]) * (x - t[j]) / (t[j + 1] - t[j])
      d = y - (f[2] + 0); if (d < 0) d = -d; if (d > worst) worst = d }
    END { printf "%.2f", worst * 1000 }' "$1" "$2"
}

cases=()
for len in "${lengths[@]}"; do
  link "$len" "$work/clamp_${len}m.cir"
  cases+=("$work/clamp_${len}m.cir|v(rxp,rxn)")
done
cases+=("tests/cli/data/nonlinear/clipper_zener.cir|v(out)"
  "tests/cli/data/nonlinear/rectifier_rc.cir|v(out)"
  "tests/cli/data/nonlinear/esd_pulse.cir|v(pin)"
  "tests/cli/data/nonlinear/link_clamp_cm_step.cir|v(rxp,rxn)")

echo "<!-- $(date -u "+%Y-%m-%d %H:%M") UTC, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), N=$N -->"
printf '| circuit | unknowns | port model ms | transient ms | ngspice ms | ngspice / port model | port model dev (mV) | transient dev (mV) | ngspice dev (mV) | port model steps |\n'
printf '|---|---|---|---|---|---|---|---|---|---|\n'
for c in "${cases[@]}"; do
  file=${c%%|*} probe=${c#*|}
  name=$(basename "$file" .cir)
  "$ISOLINK" sim "$file" -p "$probe" --engine transient --reltol 1e-6 -o "$work/ref.csv" 2>/dev/null
  stats=$("$ISOLINK" sim "$file" -p "$probe" -o "$work/port.csv" 2>&1 >/dev/null || true)
  unknowns=$(grep -o '[0-9]* unknowns' <<<"$stats" | head -1 | cut -d' ' -f1)
  steps=$(grep -o '[0-9]* steps accepted' <<<"$stats" | head -1 | cut -d' ' -f1)
  grep -q 'port model engine' <<<"$stats" || steps="(not port: $(grep -o 'because.*' <<<"$stats" | head -c 80))"
  "$ISOLINK" sim "$file" -p "$probe" --engine transient -o "$work/tran.csv" 2>/dev/null
  ngdeck "$file" "$work/deck.cir" "$work/ng.txt" "$probe"
  ngspice -b "$work/deck.cir" >/dev/null 2>&1 || true
  t_port=$(best "$ISOLINK" sim "$file" -p "$probe" -o "$work/p2.csv")
  t_tran=$(best "$ISOLINK" sim "$file" -p "$probe" --engine transient -o "$work/t2.csv")
  t_ng=$(best ngspice -b "$work/deck.cir")
  ratio=$(awk -v a="$t_ng" -v b="$t_port" 'BEGIN { printf "%.1f", (b > 0 ? a / b : 0) }')
  printf '| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n' "$name" "$unknowns" "$t_port" \
    "$t_tran" "$t_ng" "$ratio" "$(maxdev "$work/port.csv" "$work/ref.csv")" \
    "$(maxdev "$work/tran.csv" "$work/ref.csv")" "$(maxdev "$work/ng.txt" "$work/ref.csv")" "$steps"
done
