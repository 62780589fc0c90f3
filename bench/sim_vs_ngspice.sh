#!/usr/bin/env bash
# isolink sim (LTI engine and transient engine) against ngspice, all in one run:
#   bash bench/sim_vs_ngspice.sh [ISOLINK_BINARY] [N] [EXAMPLE...]
# (defaults: build/cli/isolink, N=5, every netlists/examples/*.cir, then the link specs
# netlists/examples/{transformer_15m,hybrid_xfmr_cap_12m}.yaml and bench/links/*.yaml exported with
# `isolink export-spice` (down direction)). An EXAMPLE is a .cir or a link spec .yaml. For each:
#   - `isolink sim --engine lti` and `isolink sim --engine transient`, each with its default
#     options, wall time best of N (process start-up included);
#   - ngspice with its default options plus `.options rshunt=1e12` (it cannot solve the floating
#     nodes otherwise), wall time best of N;
#   - ngspice once at tight tolerances (reltol 1e-6, abstol 1e-12, vntol 1e-9, trtol 1) as the
#     reference (trtol 1 as the tests use: at its default 7, ngspice at reltol 1e-6 is itself 5.8 mV
#     from converged ngspice on the 20 m link);
#   - max |v(rxp,rxn) - reference| over the reference's time points (the other waveform
#     interpolated linearly), in mV, for isolink and for default ngspice.
# With WINDOW=T (seconds, e.g. WINDOW=6e-6) it also runs ngspice converged (reltol 1e-7, abstol
# 1e-13, vntol 1e-10, trtol 1, tmax 0.1 ns) over the first T of each example and prints a second
# table: the deviation of every run above from that converged reference over [0, T].
# Prints a Markdown table (for bench/README.md). Both programs write v(rxp,rxn) to a file, so the
# wall times include parsing and output on both sides.
set -euo pipefail
cd "$(dirname "$0")/.."
ISOLINK=${1:-build/cli/isolink}
N=${2:-5}
shift $(($# < 2 ? $# : 2))
if (($# > 0)); then
  examples=("$@")
else
  examples=(netlists/examples/*.cir netlists/examples/transformer_15m.yaml
    netlists/examples/hybrid_xfmr_cap_12m.yaml bench/links/*.yaml)
fi
PROBE='v(rxp,rxn)'
TIGHT='.options reltol=1e-6 abstol=1e-12 vntol=1e-9 trtol=1 rshunt=1e12'
CONVERGED='.options reltol=1e-7 abstol=1e-13 vntol=1e-10 trtol=1 rshunt=1e12'
WINDOW=${WINDOW:-}
window_rows=""
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

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

ngdeck() {  # netlist options deck data: the netlist without .end, options, a .control block
  sed '/^\.[eE][nN][dD]\s*$/d' "$1" >"$3"
  printf '%s\n.control\nset wr_singlescale\noption numdgt=12\nrun\nwrdata %s %s\n.endc\n.end\n' \
    "$2" "$4" "$PROBE" >>"$3"
}

# max |test - ref| in mV over ref's time points, test interpolated linearly (col 1 time, col 2
# value; CSV or whitespace; non-numeric lines skipped; times must increase)
maxdev() {
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

rows() { awk 'NF && $1 ~ /^[-+0-9.eE]+,?/' "$1" | wc -l; }

echo "<!-- $(date -u +%Y-%m-%d), $(nproc) cores, $(uname -m), load $(cut -d' ' -f1-3 /proc/loadavg), N=$N -->"
printf '| example | unknowns | LTI ms | transient ms | ngspice ms | ngspice / LTI | ngspice / transient | LTI max dev (mV) | transient max dev (mV) | ngspice max dev (mV) | LTI rows | transient steps | ngspice points | reference points |\n'
printf '|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n'
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", (b > 0 ? a / b : 0) }'; }
for file in "${examples[@]}"; do
  name=$(basename "$file" .cir)
  if [[ "$file" == *.yaml ]]; then  # a link spec: its exported netlist (down direction)
    name=$(basename "$file" .yaml)
    "$ISOLINK" export-spice "$file" -o "$work/$name.cir"
    file="$work/$name.cir"
  fi
  summary=$("$ISOLINK" sim "$file" --probe "$PROBE" --engine transient -o "$work/tr.csv" 2>&1 >/dev/null || true)
  unknowns=$(sed -n 's/.* \([0-9]*\) unknowns.*/\1/p' <<<"$summary" | head -1)
  t_lti=$(best "$ISOLINK" sim "$file" --probe "$PROBE" --engine lti -q -o "$work/lti.csv")
  t_tr=$(best "$ISOLINK" sim "$file" --probe "$PROBE" --engine transient -q -o "$work/tr.csv")
  ngdeck "$file" '.options rshunt=1e12' "$work/ng.cir" "$work/ng.txt"
  t_ng=$(best ngspice -b "$work/ng.cir")
  ngdeck "$file" "$TIGHT" "$work/ref.cir" "$work/ref.txt"
  ngspice -b "$work/ref.cir" >"$work/ref.log" 2>&1 || true
  if [[ ! -s "$work/ref.txt" || ! -s "$work/ng.txt" || ! -s "$work/lti.csv" || ! -s "$work/tr.csv" ]]; then
    printf '| %s | run failed | | | | | | | | | | | | |\n' "$name"
    continue
  fi
  if [[ -n "$WINDOW" ]]; then  # converged ngspice over [0, WINDOW]: .tran 0.1n WINDOW 0 0.1n
    ngdeck "$file" "$CONVERGED" "$work/conv.cir" "$work/conv.txt"
    sed -i "s/^\.[tT][rR][aA][nN]\s.*$/.tran 1e-10 $WINDOW 0 1e-10/" "$work/conv.cir"
    ngspice -b "$work/conv.cir" >"$work/conv.log" 2>&1 || true
    if [[ -s "$work/conv.txt" ]]; then
      window_rows+="| $name | $WINDOW | $(maxdev "$work/lti.csv" "$work/conv.txt") | \
$(maxdev "$work/tr.csv" "$work/conv.txt") | $(maxdev "$work/ng.txt" "$work/conv.txt") | \
$(maxdev "$work/ref.txt" "$work/conv.txt") | $(($(rows "$work/conv.txt") - 1)) |"$'\n'
    else
      window_rows+="| $name | $WINDOW | converged run failed | | | | |"$'\n'
    fi
  fi
  printf '| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n' "$name" "$unknowns" \
    "$t_lti" "$t_tr" "$t_ng" "$(ratio "$t_ng" "$t_lti")" "$(ratio "$t_ng" "$t_tr")" \
    "$(maxdev "$work/lti.csv" "$work/ref.txt")" "$(maxdev "$work/tr.csv" "$work/ref.txt")" \
    "$(maxdev "$work/ng.txt" "$work/ref.txt")" "$(($(rows "$work/lti.csv") - 1))" \
    "$(($(rows "$work/tr.csv") - 1))" "$(($(rows "$work/ng.txt") - 1))" "$(($(rows "$work/ref.txt") - 1))"
done
if [[ -n "$WINDOW" ]]; then
  printf '\nOver the first %s s, max |v(rxp,rxn) - converged ngspice| (mV):\n\n' "$WINDOW"
  printf '| example | window (s) | LTI | transient | ngspice default | ngspice reltol 1e-6 trtol 1 (the reference above) | converged points |\n'
  printf '|---|---|---|---|---|---|---|\n'
  printf '%s' "$window_rows"
fi
