#!/usr/bin/env bash
# A compiler launcher that times each translation unit: where a build's minutes go, unit by unit
# (docs/reliability.md, "Where the build minutes go"). It runs the compile command it is given
# (no ccache: every unit is compiled cold) and appends "<wall seconds> <object file>" to
# $KERF_UNIT_TIMES (default build-unit-times.txt in the working directory of the build step).
#
#   cmake -S . -B build-timed -DCMAKE_BUILD_TYPE=Release \
#         -DCMAKE_CXX_COMPILER_LAUNCHER="$PWD/experiments/benchmarks/time_units.sh"
#   KERF_UNIT_TIMES=/tmp/units.txt cmake --build build-timed -j2 [--target kerf kerf-rig]
#   sort -rn /tmp/units.txt | head
set -u
out=""
previous=""
for argument in "$@"; do
  [ "$previous" = "-o" ] && out="$argument"
  previous="$argument"
done
start=$(date +%s%N)
"$@"
status=$?
end=$(date +%s%N)
seconds=$(awk -v ns=$((end - start)) 'BEGIN { printf "%.2f", ns / 1e9 }')
echo "$seconds $out" >> "${KERF_UNIT_TIMES:-build-unit-times.txt}"
exit $status
