#!/usr/bin/env bash
# The floors of the tree (README, "Layout"): meshes < realtime, reference < experiments < viewer <
# apps. A file includes only its own floor or lower ones, and realtime and reference, side by side
# on the second floor, include nothing of each other. Checks every #include "…" of the sources.
# Usage: includes_run_downward.sh SOURCE_DIR
set -euo pipefail
cd "$1"
floor() {
  case $1 in
    meshes) echo 0 ;;
    realtime | reference) echo 1 ;;
    experiments) echo 2 ;;
    viewer) echo 3 ;;
    apps) echo 4 ;;
    *) echo -1 ;;
  esac
}
bad=0
checked=0
while IFS= read -r line; do
  file=${line%%:*}
  target=$(sed -n 's/.*#include "\([^"]*\)".*/\1/p' <<< "${line#*:}")
  from=${file%%/*}
  to=${target%%/*}
  f=$(floor "$from")
  t=$(floor "$to")
  [[ $f -lt 0 || $t -lt 0 ]] && continue
  checked=$((checked + 1))
  if [[ $t -gt $f || ($f -eq 1 && $t -eq 1 && $from != "$to") ]]; then
    echo "$file includes $target: a file includes its own floor or lower ones (meshes < realtime, reference < experiments < viewer < apps), and realtime and reference nothing of each other" >&2
    bad=1
  fi
done < <(grep -rn --include='*.hpp' --include='*.cpp' '^#include "' meshes realtime reference experiments viewer apps)
echo "includes_run_downward: $checked includes between floors checked"
[[ $checked -gt 0 ]] || { echo "no includes found under $1" >&2; exit 1; }
exit $bad
