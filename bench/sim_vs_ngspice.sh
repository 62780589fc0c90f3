#!/usr/bin/env bash
# Times `isolink sim` and ngspice on the same netlists in the same run (wall time, best of N).
#   bash bench/sim_vs_ngspice.sh [build/cli/isolink] [N]
# Both simulators write the same probes to a file; ngspice gets `.options rshunt=1e12` (it cannot
# solve the floating cable nodes otherwise) and its defaults otherwise (reltol 1e-3, trtol 7).
set -euo pipefail
cd "$(dirname "$0")/.."
ISOLINK=${1:-build/cli/isolink}
N=${2:-5}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

best() {  # best wall time in ms of N runs of "$@"
  local b=999999
  for _ in $(seq "$N"); do
    local s e
    s=$(date +%s%N)
    "$@" >/dev/null 2>&1 || true
    e=$(date +%s%N)
    local ms=$(((e - s) / 1000000))
    ((ms < b)) && b=$ms
  done
  echo "$b"
}

printf '| netlist | probes | isolink ms | isolink steps | ngspice ms | ngspice points |\n|---|---|---|---|---|---|\n'
for spec in "netlists/examples/cap_link_2m.cir:v(rxp,rxn) v(txp,txn)" \
            "tests/cli/data/transformer.cir:v(s1,s2)" \
            "tests/cli/data/rlc_ladder.cir:v(b) v(d)"; do
  file=${spec%%:*}
  probes=${spec#*:}
  args=()
  for p in $probes; do args+=(--probe "$p"); done
  t_iso=$(best "$ISOLINK" sim "$file" "${args[@]}" -q -o "$work/iso.csv")
  steps=$(("$(wc -l <"$work/iso.csv")" - 1))
  deck="$work/deck.cir"
  sed '/^\.[eE][nN][dD]\s*$/d' "$file" >"$deck"
  printf '.options rshunt=1e12\n.control\nset wr_singlescale\nrun\nwrdata %s %s\n.endc\n.end\n' "$work/ng.txt" "$probes" >>"$deck"
  t_ng=$(best ngspice -b "$deck")
  points=$(("$(wc -l <"$work/ng.txt")"))
  printf '| %s | %s | %s | %s | %s | %s |\n' "$file" "$probes" "$t_iso" "$steps" "$t_ng" "$points"
done
