#!/usr/bin/env bash
# Start-up and a small simulation, isolink against ngspice, in one run:
#   bash bench/startup.sh [ISOLINK_BINARY] [N] [NETLIST]
# (defaults: build/cli/isolink, N=20, netlists/examples/cap_link_2m.cir). Wall time (best and
# median of N) and CPU time (user + sys, best of N) of:
#   - `isolink --help`, `isolink frame ...` (commands that draw nothing: start-up only);
#   - `ngspice -v` (ngspice's start-up);
#   - `isolink sim NETLIST -p v(rxp,rxn) -o FILE` against `ngspice -b` on the same netlist (with
#     `.options rshunt=1e12` and a wrdata of the same probe), both at their default tolerances;
# and the number of shared libraries each program loads (ldd), with the image plug-in's beside.
# BASELINE=OTHER_ISOLINK adds `OTHER_ISOLINK --help` (e.g. a build that links OpenImageIO) to the
# same run. Prints a Markdown table for bench/README.md.
set -euo pipefail
cd "$(dirname "$0")/.."
ISOLINK=${1:-build/cli/isolink}
N=${2:-20}
NETLIST=${3:-netlists/examples/cap_link_2m.cir}
PROBE='v(rxp,rxn)'
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

times() {  # "wall best | wall median | CPU best" in ms of N runs of "$@" (CPU = user + sys of the
  # process, from getrusage: on a loaded machine the wall time waits for a core, the CPU time not)
  python3 - "$N" "$@" <<'PY'
import resource, statistics, subprocess, sys, time
n, cmd = int(sys.argv[1]), sys.argv[2:]
wall, cpu = [], []
for _ in range(n):
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall.append((time.perf_counter() - t0) * 1e3)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu.append((r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime) * 1e3)
print(f"{min(wall):.1f} | {statistics.median(wall):.1f} | {min(cpu):.1f}", end="")
PY
}

sed '/^\.[eE][nN][dD]\s*$/d' "$NETLIST" >"$work/deck.cir"
printf '.options rshunt=1e12\n.control\nset wr_singlescale\nrun\nwrdata %s %s\n.endc\n.end\n' \
  "$work/ng.txt" "$PROBE" >>"$work/deck.cir"

plugin=$(dirname "$(readlink -f "$ISOLINK")")/../reports/libisolink_images.so
libs() { ldd "$1" 2>/dev/null | grep -c '=>' || true; }

echo "<!-- $(date -u +%Y-%m-%d), $(nproc) cores, $(uname -m), load $(cut -d' ' -f1-3 /proc/loadavg), N=$N -->"
echo "| command | wall best ms | wall median ms | CPU best ms |"
echo "|---|---|---|---|"
echo "| \`isolink --help\` | $(times "$ISOLINK" --help) |"
echo "| \`isolink frame \"stack-write reg=0x0100 data=02B778BC\"\` | $(times "$ISOLINK" frame "stack-write reg=0x0100 data=02B778BC") |"
if [ -n "${BASELINE:-}" ]; then
  echo "| \`isolink --help\`, baseline $BASELINE ($(libs "$BASELINE") libraries) | $(times "$BASELINE" --help) |"
fi
echo "| \`ngspice -v\` | $(times ngspice -v) |"
echo "| \`isolink sim $(basename "$NETLIST") -p '$PROBE' -o FILE\` | $(times "$ISOLINK" sim "$NETLIST" -p "$PROBE" -o "$work/iso.csv" -q) |"
echo "| \`ngspice -b\` on the same netlist (wrdata $PROBE) | $(times ngspice -b "$work/deck.cir") |"
echo
echo "Shared libraries loaded (ldd): isolink $(libs "$ISOLINK"), ngspice $(libs "$(command -v ngspice)"), image plug-in $(libs "$plugin") (loaded only when a PNG is drawn)."
