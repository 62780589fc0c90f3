#!/usr/bin/env bash
# isolink sim --engine lti against ngspice at its defaults on the long links of the random corpus
# (issue 28, item 5: links of 10 m or more, up to 50 m, every isolation type), each pair timed
# back to back in one run:
#   bash bench/speed_corpus.sh [N] [COUNT] [SEED]    # defaults 3, 12, 1
# The first COUNT specs of `tools/link_corpus.py --seed SEED` whose cable is 10-50 m, exported
# with `isolink export-spice` (down direction) and run both ways, writing v(rxp,rxn) to a file:
#   - isolink: `isolink sim FILE --engine lti -p 'v(rxp,rxn)' -o out.csv`;
#   - ngspice: the same netlist with `.options rshunt=1e12` (it cannot solve the floating nodes
#     otherwise) and `wrdata` of v(rxp,rxn), `ngspice -b`.
# Wall time best of N (NG_N for ngspice; process start-up, parsing and the output file included on both sides) and
# CPU time (user + system, GNU time) of the best run's kind: on a shared machine the CPU ratio is
# the one that carries over. Prints a Markdown table with the median and smallest ratio, and the
# engine line isolink printed (the reduced model's order, or why it marched). The accuracy of the
# same engine on the same corpus is bench/lti_corpus.sh's and tests/analysis/fast_path_test.cpp's.
# ISOLINK=PATH runs another binary than build/cli/isolink. SPECS="049 166" runs those specs
# instead (any length; e.g. the slowest directions of bench/lti_corpus.sh); LINKS="a.yaml b.yaml"
# runs those link specs (bench/ngspice_links/: issue 41's two long linear links).
set -euo pipefail
cd "$(dirname "$0")/.."
N=${1:-3} COUNT=${2:-12} SEED=${3:-1}
NG_N=${NG_N:-$N}  # ngspice's runs (each takes minutes on the long links: NG_N=1 saves them)
ISOLINK=${ISOLINK:-build/cli/isolink}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 tools/link_corpus.py --seed "$SEED" --first 0 --count 300 --out "$work"

# best wall ms and the CPU ms of that run, of N runs of "$@"
best() {
  local b=999999999 c=0 s e ms cpu
  for _ in $(seq "$N"); do
    s=$(date +%s%N)
    /usr/bin/time -f '%U %S' -o "$work/time" "$@" >/dev/null 2>&1 || true
    e=$(date +%s%N)
    ms=$(((e - s) / 1000000))
    cpu=$(tail -1 "$work/time" | awk '{ printf "%d", ($1 + $2) * 1000 }')
    if ((ms < b)); then b=$ms c=$cpu; fi
  done
  echo "$b $c"
}

echo "<!-- $(date -u +%Y-%m-%dT%H:%MZ), $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg), N=$N, seed $SEED -->"
echo "| spec | length (m) | tx / rx isolation | unknowns | isolink ms (CPU) | ngspice ms (CPU) | wall ratio | CPU ratio | isolink engine |"
echo "|---|---|---|---|---|---|---|---|---|"
ratios=() cpu_ratios=() done_count=0
if [[ -n ${LINKS:-} ]]; then
  read -r -a specs <<<"$LINKS"
  COUNT=${#specs[@]}
elif [[ -n ${SPECS:-} ]]; then
  specs=() && for i in $SPECS; do specs+=("$work/link_$i.yaml"); done
  COUNT=${#specs[@]}
else
  specs=("$work"/link_*.yaml)
fi
for spec in "${specs[@]}"; do
  ((done_count >= COUNT)) && break
  len=$(sed -n 's/^cable: {length: \([0-9.]*\).*/\1/p' "$spec")
  [[ -n ${SPECS:-}${LINKS:-} ]] || awk -v l="$len" 'BEGIN { exit !(l >= 10 && l <= 50) }' || continue
  name=$(basename "$spec" .yaml)
  iso=$(sed -n 's/^\(tx\|rx\):.*type: \([a-z]*\).*/\2/p' "$spec" | paste -sd/)
  "$ISOLINK" export-spice "$spec" --direction down -o "$work/l.cir" >/dev/null 2>&1
  line=$("$ISOLINK" sim "$work/l.cir" --engine lti -p 'v(rxp,rxn)' -o "$work/lti.csv" 2>&1 |
    grep 'isolink sim' | head -1 || true)
  unknowns=$(sed -n 's/.* \([0-9]*\) unknowns.*/\1/p' <<<"$line" | head -1)
  engine=$(grep -o 'order [0-9]* ([0-9]* poles, [0-9]* expansion points)\|march[^;]*' <<<"$line" |
    head -1 || true)
  sed '/^\.[eE][nN][dD]\s*$/d' "$work/l.cir" >"$work/ng.cir"
  printf '.options rshunt=1e12\n.control\nset wr_singlescale\nrun\nwrdata %s v(rxp,rxn)\n.endc\n.end\n' \
    "$work/ng.txt" >>"$work/ng.cir"
  read -r li_ms li_cpu < <(best "$ISOLINK" sim "$work/l.cir" --engine lti -q -p 'v(rxp,rxn)' -o "$work/lti.csv")
  read -r ng_ms ng_cpu < <(N=$NG_N best ngspice -b "$work/ng.cir")
  r=$(awk -v a="$ng_ms" -v b="$li_ms" 'BEGIN { printf "%.1f", a / b }')
  rc=$(awk -v a="$ng_cpu" -v b="$li_cpu" 'BEGIN { printf "%.1f", (b > 0 ? a / b : 0) }')
  ratios+=("$r") cpu_ratios+=("$rc")
  echo "| $name | $len | $iso | $unknowns | $li_ms ($li_cpu) | $ng_ms ($ng_cpu) | $r | $rc | $engine |"
  done_count=$((done_count + 1))
done
stats() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { printf "median %.1f, smallest %.1f", (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2), v[1] }'; }
echo
echo "ngspice / isolink over ${#ratios[@]} links: wall $(stats "${ratios[@]}"); CPU $(stats "${cpu_ratios[@]}")"
