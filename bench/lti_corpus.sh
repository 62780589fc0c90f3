#!/usr/bin/env bash
# The random link corpus (tools/link_corpus.py) through the LTI engine: for every spec and both
# directions, the exported netlist on `isolink sim --engine lti`, and whether the reduced model
# passed its check (else the march ran, and its note says why).
#   bash bench/lti_corpus.sh [FIRST] [LAST] [SEED]    # defaults 0 299 1; prints a line per direction
# (ISOLINK=PATH runs another binary than build/cli/isolink)
set -euo pipefail
cd "$(dirname "$0")/.."
first=${1:-0} last=${2:-299} seed=${3:-1}
bin=${ISOLINK:-build/cli/isolink}  # ISOLINK=PATH: another binary
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 tools/link_corpus.py --seed "$seed" --first "$first" --count $((last - first + 1)) \
  --out "$work"
ok=0 march=0
for i in $(seq -f %03g "$first" "$last"); do
  for d in down up; do
    "$bin" export-spice "$work/link_$i.yaml" --direction "$d" -o "$work/l.cir" >/dev/null
    out=$("$bin" sim "$work/l.cir" --engine lti -p 'v(rxp,rxn)' -o /dev/null 2>&1 | grep 'isolink sim')
    if grep -q 'reduced model:' <<<"$out"; then
      ok=$((ok + 1))
      echo "$i $d reduced $(grep -o 'order [0-9]*' <<<"$out" | head -1) $(grep -o '[0-9.]* s;' <<<"$out")"
    else
      march=$((march + 1))
      echo "$i $d MARCH $(grep -o "march ran because.*" <<<"$out")"
    fi
  done
done
echo "reduced model: $ok directions, march: $march"
