#!/usr/bin/env bash
# The floors of the tree (README, "Layout"): meshes < realtime, reference < experiments < viewer <
# apps. A file includes only its own floor or lower ones, and realtime and reference, side by side
# on the second floor, include nothing of each other. Inside experiments the folders have floors of
# their own: trajectory, profile < scene < models < records < reference_run, calibration < study <
# benchmarks (reference_run and calibration side by side, neither including the other). Checks
# every #include "…" of the sources.
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
# The floors of experiments' folders.
inner_floor() {
  case $1 in
    trajectory | profile) echo 0 ;;
    scene) echo 1 ;;
    models) echo 2 ;;
    records) echo 3 ;;
    reference_run | calibration) echo 4 ;;
    study) echo 5 ;;
    benchmarks) echo 6 ;;
    *) echo -1 ;;
  esac
}
bad=0
checked=0
inner_checked=0
while IFS= read -r line; do
  file=${line%%:*}
  target=$(sed -n 's/.*#include "\([^"]*\)".*/\1/p' <<< "${line#*:}")
  from=${file%%/*}
  to=${target%%/*}
  f=$(floor "$from")
  t=$(floor "$to")
  [[ $f -lt 0 || $t -lt 0 ]] && continue
  if [[ $from == experiments && $to == experiments ]]; then
    rest=${file#experiments/}
    inner_from=${rest%%/*}
    rest=${target#experiments/}
    inner_to=${rest%%/*}
    fi_=$(inner_floor "$inner_from")
    ti_=$(inner_floor "$inner_to")
    if [[ $fi_ -lt 0 || $ti_ -lt 0 ]]; then
      echo "$file includes $target: experiments/$inner_from or experiments/$inner_to has no floor in includes_run_downward.sh" >&2
      bad=1
    elif [[ $inner_from != "$inner_to" ]]; then
      inner_checked=$((inner_checked + 1))
      if [[ $ti_ -gt $fi_ || ($ti_ -eq $fi_) ]]; then
        echo "$file includes $target: inside experiments a folder includes only lower floors (trajectory, profile < scene < models < records < reference_run, calibration < study < benchmarks)" >&2
        bad=1
      fi
    fi
  fi
  checked=$((checked + 1))
  if [[ $t -gt $f || ($f -eq 1 && $t -eq 1 && $from != "$to") ]]; then
    echo "$file includes $target: a file includes its own floor or lower ones (meshes < realtime, reference < experiments < viewer < apps), and realtime and reference nothing of each other" >&2
    bad=1
  fi
done < <(grep -rn --include='*.hpp' --include='*.cpp' '^#include "' meshes realtime reference experiments viewer apps)
echo "includes_run_downward: $checked includes between floors checked, $inner_checked between experiments' folders"
[[ $checked -gt 0 ]] || { echo "no includes found under $1" >&2; exit 1; }
exit $bad
