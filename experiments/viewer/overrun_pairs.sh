#!/usr/bin/env bash
# The servo loop's deadline misses without and with the live view (docs/viewer.md, "Why the servo
# misses deadlines here"): N pairs of `kerf view` sessions, alternating --no-view and the view
# rendering off screen, each printing its overruns and missed deadlines, the hypervisor's steal
# time over the session (jiffies, /proc/stat) and the load average.
#
#   bash experiments/viewer/overrun_pairs.sh sponge_cut_constant voxel "" 8
#   bash experiments/viewer/overrun_pairs.sh clay_pull springs "--model-rate 100" 8
#
# The viewed sessions use the X display in DISPLAY, else a private Xvfb started here.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
kerf="${KERF:-$here/build/apps/kerf/kerf}"
scene="$1" model="$2" extra="$3" pairs="${4:-8}"
if [ -z "${DISPLAY:-}" ]; then
  Xvfb :97 -screen 0 1600x1200x24 -nolisten tcp -noreset >/dev/null 2>&1 &
  xvfb=$!
  trap 'kill $xvfb' EXIT
  export DISPLAY=:97
  sleep 1
fi
steal() { awk '/^cpu /{print $9}' /proc/stat; }
for i in $(seq 1 "$pairs"); do
  for mode in without with; do
    s0=$(steal)
    # shellcheck disable=SC2086
    if [ "$mode" = without ]; then out=$("$kerf" view "$scene" --model "$model" $extra --no-view 2>&1)
    else out=$("$kerf" view "$scene" --model "$model" $extra --offscreen --width 640 --height 480 2>&1); fi
    s1=$(steal)
    echo "pair $i, $mode the view: $(echo "$out" | grep -o '[0-9]* overruns, [0-9]* missed deadlines'); $(echo "$out" | grep -o 'woken late.*' | sed 's/  */ /g'); steal $((s1 - s0)) jiffies; load $(cut -d' ' -f1 /proc/loadavg)"
  done
done
