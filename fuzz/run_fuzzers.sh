#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/CMakeLists.txt: clang-14, only the parsers) and runs each for
# a bounded time on its seed corpus (written into the build tree from the repository's scenes).
# A crash, an undocumented exception, a broken invariant, a sanitizer report, a leak, a hang
# (> 60 s on one input; the largest valid input, a recorded trajectory of 1e7 samples, takes
# ~17 s in this instrumented build) or more than 2 GB RSS fails the run; the input is saved under
# BUILD/fuzz/crashes/TARGET/ (add it to fuzz/regressions/TARGET/ with the fix).
#
#   bash fuzz/run_fuzzers.sh [SECONDS_PER_TARGET [TARGET...]]    # default 30 s, every target
#   bash fuzz/run_fuzzers.sh --campaign CPU_SECONDS [TARGET...]    # the long campaign
#   bash fuzz/run_fuzzers.sh --minimise [TARGET...]                # re-minimise the kept corpora
#
# Every run also reads the kept corpus fuzz/corpus/TARGET/ (committed; read only in a short run):
# the smallest inputs that add coverage to the seeds (written into the build tree at build time).
# A campaign runs each target until it has spent CPU_SECONDS of CPU time in total, counted over
# every campaign run of that target in fuzz/campaign.tsv (so it resumes where it was stopped, and a
# niced run on a busy machine counts only the CPU it got). Each chunk appends one line to the ledger
# (target, CPU seconds, executions, finding or none, libFuzzer's coverage), then the kept corpus is
# minimised (below) with what the chunk found. Commit both.
#
# Minimising (after a campaign chunk, or --minimise alone): libFuzzer's -merge=1 with the seeds as
# the corpus already held, so the kept corpus becomes the inputs that add coverage to the seeds,
# taken smallest first, from the kept corpus and the build tree's corpus/TARGET/ (what runs in this
# build folder found). --minimise also prints the coverage (edges, features) of the seeds and kept
# corpus before and after.
#
# KERF_FUZZ_BUILD_DIR overrides the build folder (default: build-fuzz beside the sources);
# KERF_FUZZ_SEED fixes libFuzzer's random seed (CI: 1; default 0, a new seed each run).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${KERF_FUZZ_BUILD_DIR:-$here/build-fuzz}"
campaign=0
minimise_only=0
if [ "${1:-}" = "--campaign" ]; then campaign=1; shift; fi
if [ "${1:-}" = "--minimise" ]; then minimise_only=1; shift; set -- 0 "$@"; fi
seconds="${1:-30}"
shift || true
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(device_protocol quantity scene trajectory_csv session_csv profile_csv study parameter_file study_table reference_checkpoint replay)

cmake -S "$here" -B "$build" -DKERF_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=RelWithDebInfo > /dev/null
cmake --build "$build" -j2

ledger="$here/fuzz/campaign.tsv"
[ -f "$ledger" ] || printf 'target\tcpu_seconds\texecutions\tresult\tcoverage\n' > "$ledger"
# CPU seconds (user + system) one process has used so far, from /proc/PID/stat fields 14 and 15.
cpu_seconds_of() { awk -v hz="$(getconf CLK_TCK)" '{ print int(($14 + $15) / hz) }' "/proc/$1/stat" 2> /dev/null || echo 0; }
spent_on() { awk -F'\t' -v t="$1" '$1 == t { s += $2 } END { print s + 0 }' "$ledger"; }

# minimise TARGET: the kept corpus becomes the smallest inputs of the kept corpus and the build's
# corpus that add coverage to the seeds (libFuzzer's -merge=1 keeps every input of its first folder,
# here a copy of the seeds, and adds the others smallest first when they bring a new feature).
minimise() {
  local t=$1 seeds="$build/fuzz/seeds/$1" merged="$build/fuzz/merged/$1" kept="$here/fuzz/corpus/$1"
  rm -rf "$merged"; mkdir -p "$merged"
  cp -r "$seeds"/. "$merged"/
  if ! "$build/fuzz/fuzz_$t" -merge=1 -timeout=60 -rss_limit_mb=2048 "$merged" "$kept" "$build/fuzz/corpus/$t" \
         > "$build/fuzz/$t.merge.log" 2>&1; then
    echo "fuzz_$t: the merge failed (log $build/fuzz/$t.merge.log); the kept corpus is unchanged"
    return 1
  fi
  (cd "$seeds" && find . -type f -exec rm -f "$merged/{}" \;)
  rm -rf "$kept"; mv "$merged" "$kept"
}
size_of() { find "$1" -type f -printf '%s\n' | awk '{ n++; b += $1 } END { printf "%d files, %d bytes", n, b }'; }
# coverage TARGET: libFuzzer's coverage of the seeds and the kept corpus, "cov: EDGES ft: FEATURES".
coverage() {
  "$build/fuzz/fuzz_$1" -runs=0 -timeout=60 -rss_limit_mb=2048 "$here/fuzz/corpus/$1" "$build/fuzz/seeds/$1" 2>&1 |
    grep -oE 'INITED cov: [0-9]+ ft: [0-9]+' | sed 's/INITED //'
}

status=0
for t in "${targets[@]}"; do
  corpus="$build/fuzz/corpus/$t"
  crashes="$build/fuzz/crashes/$t"
  kept="$here/fuzz/corpus/$t"
  mkdir -p "$corpus" "$crashes" "$kept"
  log="$build/fuzz/$t.log"
  if [ $minimise_only -eq 1 ]; then
    before="$(coverage "$t"); kept $(size_of "$kept")"
    minimise "$t" || status=1
    echo "fuzz_$t: seeds and kept corpus before: $before; after: $(coverage "$t"); kept $(size_of "$kept")"
    continue
  fi
  if [ $campaign -eq 1 ]; then
    budget=$((seconds - $(spent_on "$t")))
    if [ $budget -le 0 ]; then echo "fuzz_$t: campaign done ($(spent_on "$t") CPU s in $ledger)"; continue; fi
    # New inputs go to corpus/ in the build; the kept corpus and the seeds are read only.
    started="$build/fuzz/$t.started"; touch "$started"
    "$build/fuzz/fuzz_$t" -timeout=60 -rss_limit_mb=2048 -print_final_stats=1 -seed="${KERF_FUZZ_SEED:-0}" \
      -artifact_prefix="$crashes/" "$corpus" "$kept" "$build/fuzz/seeds/$t" > "$log" 2>&1 &
    pid=$!
    used=0
    while kill -0 $pid 2> /dev/null; do
      sleep 5
      now=$(cpu_seconds_of $pid)
      [ "$now" -gt 0 ] && used=$now
      if [ "$used" -ge "$budget" ]; then kill -INT $pid 2> /dev/null || true; fi
    done
    rc=0; wait $pid || rc=$?
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo 0)
    cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -1 | grep -oE '[0-9]+' || echo "?")
    # libFuzzer exits 0 or 72 (interrupted) without a finding; a finding leaves a crash-, leak-,
    # timeout- or oom- file written by this chunk (a slow-unit- file is an input slower than 10 s,
    # under the 60 s hang limit: the large valid trajectories, not a finding). libFuzzer's timeout
    # is wall-clock time, so a process stopped from outside (SIGSTOP, a suspended VM) reports the
    # input it was on as a hang when it resumes: a timeout- input counts only if it hangs again when
    # re-run alone; one that does not is kept under unreproduced/ and the chunk reports it.
    new_findings=0
    for f in $(find "$crashes" -maxdepth 1 -newer "$started" \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \)); do
      if [[ $(basename "$f") == timeout-* ]] &&
         timeout 120 "$build/fuzz/fuzz_$t" -timeout=60 -rss_limit_mb=2048 -runs=1 "$f" > "$f.rerun.log" 2>&1; then
        mkdir -p "$crashes/unreproduced"; mv "$f" "$f.rerun.log" "$crashes/unreproduced/"
        echo "fuzz_$t: a timeout that does not reproduce (the process was stopped from outside?): $crashes/unreproduced/$(basename "$f")"
        [ $rc -eq 70 ] && rc=72 # libFuzzer's exit code for that timeout
        continue
      fi
      new_findings=$((new_findings + 1))
    done
    if [ $new_findings -gt 0 ] || { [ $rc -ne 0 ] && [ $rc -ne 72 ] && [ $rc -ne 130 ]; }; then
      result=finding; status=1
      echo "fuzz_$t: FINDING after $used CPU s (log $log, input in $crashes/):"
      grep -E 'ERROR|runtime error|SUMMARY|what\(\)|Test unit written' "$log" | head -8 || true
    else
      result=none
      echo "fuzz_$t: $used CPU s, $runs executions, coverage $cov, no finding ($(( $(spent_on "$t") + used )) CPU s in all)"
    fi
    printf '%s\t%s\t%s\t%s\t%s\n' "$t" "$used" "$runs" "$result" "$cov" >> "$ledger"
    minimise "$t" || status=1
    continue
  fi
  # New inputs go to corpus/ (kept between runs of one build folder); the kept corpus and seeds/ are read only.
  if "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=60 -rss_limit_mb=2048 -print_final_stats=1 \
       -seed="${KERF_FUZZ_SEED:-0}" \
       -artifact_prefix="$crashes/" "$corpus" "$kept" "$build/fuzz/seeds/$t" > "$log" 2>&1; then
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo "?")
    echo "fuzz_$t: ${seconds} s, ${runs} executions, no finding"
  else
    echo "fuzz_$t: FINDING (log $log, input in $crashes/):"
    grep -E 'ERROR|runtime error|SUMMARY|what\(\)|Test unit written' "$log" | head -8 || true
    status=1
  fi
done
exit $status
