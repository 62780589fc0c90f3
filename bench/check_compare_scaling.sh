#!/usr/bin/env bash
# Scaling of `isolink check` and `isolink compare` with the length of the traffic (issue 45: "run,
# check and compare cost at most proportionally to the traffic: 10x the frames costs at most 12x
# the time and memory"). For each N: the default link spec (2 m, capacitor isolation) with N
# repeated stack-write commands, down direction; `isolink run --no-worst --no-images` writes its
# wave.csv (the engine's rows, thinned within the stated tolerance: what a capture of the link
# looks like); then, each timed with its peak memory:
#   - `isolink check wave.csv` (decode and score every frame),
#   - `isolink compare wave.csv SPEC` (the frames decoded, replayed through the model, aligned and
#     differenced).
# Prints one Markdown row per N.
#
#   bash bench/check_compare_scaling.sh [build/cli/isolink] [N ...]    # default N: 10 100 1000
set -euo pipefail
# shellcheck source=bench/frames_spec.sh
source "$(dirname "$0")/frames_spec.sh"
exe=${1:-build/cli/isolink}
shift || true
counts=("$@")
[ ${#counts[@]} -eq 0 ] && counts=(10 100 1000)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
timed() {  # timed NAME CMD...: wall seconds and max RSS (MB) of CMD, as "S | MB | EXIT"
  local name=$1
  shift
  set +e
  /usr/bin/time -f '%e %M' -o "$work/$name.time" "$@" >"$work/$name.out" 2>"$work/$name.err"
  local rc=$?
  set -e
  read -r secs kb < <(tail -n 1 "$work/$name.time")
  echo "$secs | $((kb / 1024)) | $rc"
}
echo "| frames | wave.csv (MB) | wave.csv rows | check (s) | check max RSS (MB) | check exit | frames decoded | compare (s) | compare max RSS (MB) | compare exit | compare verdict |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for n in "${counts[@]}"; do
  spec="$work/cap_$n.yaml"
  write_frames_spec "$n" "$spec"
  "$exe" run "$spec" -o "$work/run_$n" -q --no-worst --no-images >/dev/null 2>&1 || true
  wave="$work/run_$n/wave.csv"
  mb=$(awk -v b="$(stat -c %s "$wave")" 'BEGIN{printf "%.1f", b / 1e6}')
  rows=$(($(wc -l <"$wave") - 1))
  check=$(timed check "$exe" check "$wave" --json)
  frames=$(python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print(len(j.get('commands', [])))" \
    "$work/check.out" 2>/dev/null || echo -)
  compare=$(timed compare "$exe" compare "$wave" "$spec" -o "$work/cmp_$n")
  verdict=$(head -n 1 "$work/compare.out" | awk '{print $1}')
  echo "| $n | $mb | $rows | $check | $frames | $compare | $verdict |"
done
