#!/usr/bin/env bash
# The floors of the tree (README, "Layout"): meshes < realtime, reference < formats < experiments <
# viewer < apps. A file includes only its own floor or lower ones, and realtime and reference, side
# by side on the second floor, include nothing of each other. Inside formats and experiments the
# folders have floors of their own: formats' trajectory, profile < scene; experiments' models <
# records < reference_run, calibration < study < benchmarks (reference_run and calibration side by
# side, neither including the other). Checks every #include "…" of the sources.
# Usage: includes_run_downward.sh SOURCE_DIR
set -euo pipefail
cd "$1"
floor() {
  case $1 in
    meshes) echo 0 ;;
    realtime | reference) echo 1 ;;
    formats) echo 2 ;;
    experiments) echo 3 ;;
    viewer) echo 4 ;;
    apps) echo 5 ;;
    *) echo -1 ;;
  esac
}
# The floors of the folders inside formats and inside experiments.
inner_floor() {
  case $1 in
    trajectory | profile) echo 0 ;;
    scene) echo 1 ;;
    models) echo 0 ;;
    records) echo 1 ;;
    reference_run | calibration) echo 2 ;;
    study) echo 3 ;;
    benchmarks) echo 4 ;;
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
  if [[ ($from == experiments || $from == formats) && $to == "$from" ]]; then
    rest=${file#"$from"/}
    inner_from=${rest%%/*}
    rest=${target#"$to"/}
    inner_to=${rest%%/*}
    fi_=$(inner_floor "$inner_from")
    ti_=$(inner_floor "$inner_to")
    if [[ $fi_ -lt 0 || $ti_ -lt 0 ]]; then
      echo "$file includes $target: $from/$inner_from or $to/$inner_to has no floor in includes_run_downward.sh" >&2
      bad=1
    elif [[ $inner_from != "$inner_to" ]]; then
      inner_checked=$((inner_checked + 1))
      if [[ $ti_ -gt $fi_ || ($ti_ -eq $fi_) ]]; then
        echo "$file includes $target: inside $from a folder includes only lower floors (formats: trajectory, profile < scene; experiments: models < records < reference_run, calibration < study < benchmarks)" >&2
        bad=1
      fi
    fi
  fi
  checked=$((checked + 1))
  if [[ $t -gt $f || ($f -eq 1 && $t -eq 1 && $from != "$to") ]]; then
    echo "$file includes $target: a file includes its own floor or lower ones (meshes < realtime, reference < formats < experiments < viewer < apps), and realtime and reference nothing of each other" >&2
    bad=1
  fi
done < <(grep -rn --include='*.hpp' --include='*.cpp' '^#include "' meshes realtime reference formats experiments viewer apps)
echo "includes_run_downward: $checked includes between floors checked, $inner_checked between the folders of formats and experiments"
[[ $checked -gt 0 ]] || { echo "no includes found under $1" >&2; exit 1; }
exit $bad
