#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/CMakeLists.txt: clang-14, only the parsers) and runs each for
# a bounded time on its seed corpus (written into the build tree from the repository's scenes).
# A crash, an undocumented exception, a broken invariant, a sanitizer report, a leak, a hang
# (> 60 s on one input; the largest valid input, a recorded trajectory of 1e7 samples, takes
# ~17 s in this instrumented build) or more than 2 GB RSS fails the run; the input is saved under
# BUILD/fuzz/crashes/TARGET/ (add it to fuzz/regressions/TARGET/ with the fix).
#
#   bash fuzz/run_fuzzers.sh [SECONDS_PER_TARGET [TARGET...]]    # default 30 s, every target
#
# KERF_FUZZ_BUILD_DIR overrides the build folder (default: build-fuzz beside the sources);
# KERF_FUZZ_SEED fixes libFuzzer's random seed (CI: 1; default 0, a new seed each run).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KERF_FUZZ_BUILD_DIR:-$here/build-fuzz}"
seconds="${1:-30}"
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(device_protocol quantity scene trajectory_csv session_csv profile_csv study parameter_file study_table reference_checkpoint replay)

cmake -S "$here" -B "$build" -DKERF_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=RelWithDebInfo > /dev/null
cmake --build "$build" -j2

status=0
for t in "${targets[@]}"; do
  corpus="$build/fuzz/corpus/$t"
  crashes="$build/fuzz/crashes/$t"
  mkdir -p "$corpus" "$crashes"
  log="$build/fuzz/$t.log"
  # New inputs go to corpus/ (kept between runs of one build folder); seeds/ is read only.
  if "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=60 -rss_limit_mb=2048 -print_final_stats=1 \
       -seed="${KERF_FUZZ_SEED:-0}" \
       -artifact_prefix="$crashes/" "$corpus" "$build/fuzz/seeds/$t" > "$log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz_$t: ${seconds} s, ${runs} executions, no finding"
  else
    echo "fuzz_$t: FINDING (log $log, input in $crashes/):"
    grep -E 'ERROR|runtime error|SUMMARY|what\(\)|Test unit written' "$log" | head -8 || true
    status=1
  fi
done
exit $status
