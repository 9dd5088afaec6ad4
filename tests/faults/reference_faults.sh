#!/usr/bin/env bash
# Fault injection on `kerf reference` (docs/reliability.md), through the command line
# and nothing else: clay_pull on a 5 mm mesh of linear tetrahedra (the scene as shipped, only
# element_size and element_degree changed, so one run takes seconds), 11 evenly spaced samples
# (checkpoints after samples 5 and 10).
#   1. an uninterrupted run: the profile every other run must reproduce;
#   2. SIGKILL at seeded random times (five kills), each followed by `--resume`: after
#      every kill, no output under a final name is half written; the final profile equals the
#      uninterrupted one (every column but cost_s, as written, to the last digit);
#   3. a full disk (SIGXFSZ ignored and RLIMIT_FSIZE set in the child, so writes fail as on a
#      full disk instead of killing it): a failure with a message, every finished output whole;
#      then `--resume` without the limit reproduces the profile; and a disk that fills between the
#      checkpoints after samples 5 and 10 (a byte-exact limit): `--resume` continues from sample 5;
#   4. an absurd load increment (the stylus jumps 2 m instead of 6 mm): the load path cuts back,
#      or stops with the last converged state saved (profile, manifest with the reason,
#      checkpoint), never a crash or a NaN.
#
#   reference_faults.sh KERF SCENES_DIR WORK_DIR
set -euo pipefail
kerf="$1"
scenes="$2"
work="$3"
source "$(dirname "${BASH_SOURCE[0]}")/fault_script_start.sh" "$work"
sed -e 's/^element_size = "2.5 mm"/element_size = "5 mm"/' -e 's/^element_degree = 2 /element_degree = 1 /' "$scenes/clay_pull.toml" > coarse.toml
grep -q '^element_size = "5 mm"' coarse.toml || fail "clay_pull.toml has no element_size line to coarsen"
grep -q '^element_degree = 1 ' coarse.toml || fail "clay_pull.toml has no element_degree line to set to linear"
samples=11 # evenly spaced, adaptive sampling off: the counts below are known

# Every output under a final name is whole: the profile's rows have 11 columns and end in a
# newline, the manifest is JSON, fields.pvd and every .vtu end with their closing tag.
check_whole() {
  local dir="$1"
  [ ! -e "$dir/profile.csv" ] || $py - "$dir/profile.csv" <<'PY' || fail "$dir/profile.csv is half written"
import sys
text = open(sys.argv[1]).read()
lines = text.split("\n")
assert text.endswith("\n") and lines[0] == "t,tool,px,py,pz,fx,fy,fz,mode,crack_extent,cost_s", "header or last newline"
for line in lines[1:-1]:
    assert len(line.split(",")) == 11, line
PY
  [ ! -e "$dir/manifest.json" ] || $py -c 'import json,sys; json.load(open(sys.argv[1]))' "$dir/manifest.json" \
    || fail "$dir/manifest.json is half written"
  for f in "$dir/fields.pvd" "$dir"/fields/*.vtu; do
    [ -e "$f" ] || continue
    case "$f" in *.tmp.*) continue ;; esac # a temporary file beside its final name (atomic_file.hpp)
    tail -c 64 "$f" | grep -q '</VTKFile>' || fail "$f is half written"
  done
}

# The profile without its cost column (compute seconds differ from run to run).
physics() { cut -d, -f1-10 "$1"; }

# 1. Uninterrupted.
start=$(date +%s.%N)
"$kerf" reference coarse.toml --samples $samples --adaptive 0 --no-fields -o whole > whole.log 2>&1 || { cat whole.log; fail "uninterrupted run"; }
whole_s=$($py -c "import sys; print(max(1.0, float(sys.argv[2]) - float(sys.argv[1])))" "$start" "$(date +%s.%N)")
# The loads solved: the requested samples and the trajectory's vertices between them (the pull's
# end at t = 1.6 s; docs/reference.md, "The load path follows the trajectory"), as the manifest
# counts them; each is a row of the profile and a numbered "sample k/loads" line of the log.
loads=$($py -c "import json, sys; print(json.load(open(sys.argv[1]))['solver']['load_path']['loads_solved'])" whole/manifest.json)
[ "$loads" -gt "$samples" ] || fail "the load path solved $loads loads for $samples samples: the pull's end is no load"
[ "$(wc -l < whole/profile.csv)" -eq $((loads + 1)) ] || fail "uninterrupted profile has $(wc -l < whole/profile.csv) lines for $loads loads"
check_whole whole
# The solve's own wall time (the run's last line), without the process's start and the meshing
# into the cache that only the first run does: under ASan + UBSan the first run takes 73 s of which
# the solve is 8 s, and kill times scaled to 73 s would fall after the later, cached runs end.
solve_s=$(grep -o 'wall [0-9.]* s' whole.log | tail -1 | cut -d' ' -f2)
[ -n "$solve_s" ] || { cat whole.log; fail "no solve wall time in the uninterrupted run's log"; }
echo "uninterrupted: $samples samples ($loads loads) in $whole_s s (the solve $solve_s s)"

# 2. SIGKILL at random points, then --resume (a fixed seed: the same kill times every run).
RANDOM=2026
kills=0
# Waits (at most 10 min) until LOG shows a sample whose number matches NUMBER_REGEX, or PID ends.
wait_for_sample() {
  local number="$1" log="$2" pid="$3"
  for _ in $(seq 1 30000); do
    grep -Eq "sample $number/$loads " "$log" && return
    kill -0 "$pid" 2> /dev/null || return
    sleep 0.02
  done
}
for attempt in $(seq 1 6); do
  "$kerf" reference coarse.toml --samples $samples --adaptive 0 -o killed --resume > "killed.$attempt.log" 2>&1 &
  pid=$!
  if [ "$attempt" -lt 6 ]; then
    # Attempts 1-2: once the solve has started (its first sample printed), a kill time uniform
    # in [0.02, 0.42] x the uninterrupted solve's wall time (mostly before any checkpoint).
    # Attempts 3-5: once sample 6 is solved (past the checkpoint after sample 5), uniform in
    # [0, 0.1] x it, while five samples are still to go: the kill lands and the next run
    # resumes from the checkpoint.
    if [ "$attempt" -le 2 ]; then
      wait_for_sample "[0-9]+" "killed.$attempt.log" "$pid"
      delay=$($py -c "import sys; print(float(sys.argv[1]) * (0.02 + 0.4 * int(sys.argv[2]) / 32767.0))" "$solve_s" "$RANDOM")
    else
      wait_for_sample "([6-9]|1[01])" "killed.$attempt.log" "$pid"
      delay=$($py -c "import sys; print(float(sys.argv[1]) * 0.1 * int(sys.argv[2]) / 32767.0)" "$solve_s" "$RANDOM")
    fi
    sleep "$delay"
    if kill -9 "$pid" 2> /dev/null; then
      wait "$pid" 2> /dev/null || true
      kills=$((kills + 1))
      check_whole killed
      continue
    fi
    # It finished before the kill (a fast machine): start again from nothing.
    wait "$pid" || { cat "killed.$attempt.log"; fail "run $attempt failed"; }
    rm -rf killed
    continue
  fi
  wait "$pid" || { cat "killed.$attempt.log"; fail "resumed run $attempt failed"; }
  break
done
[ "$kills" -ge 3 ] || fail "only $kills kills landed during a run: the test did not exercise resume"
grep -q 'resum' killed.*.log || fail "no run resumed from a checkpoint"
check_whole killed
diff <(physics whole/profile.csv) <(physics killed/profile.csv) || fail "the resumed profile differs from the uninterrupted one"
echo "SIGKILL: $kills kills, then --resume: the profile equals the uninterrupted one ($(find killed -name '*.tmp.*' | wc -l) temporary files left)"

# 3. A full disk: RLIMIT_FSIZE per file (bash counts 1024-byte blocks) with SIGXFSZ ignored, so
#    the first larger write fails with EFBIG as it would with ENOSPC. Two places: 64 kB with
#    fields (the second .vtu, ~120 kB, fails at sample 2) and 12 kB without (the checkpoint,
#    ~15 kB, fails at sample 5).
for limit in "64 fields" "12 no-fields"; do
  set -- $limit
  kb=$1
  flags=()
  [ "$2" = "no-fields" ] && flags=(--no-fields)
  dir="full_$kb"
  set +e
  ( trap '' XFSZ; ulimit -f "$kb"; exec "$kerf" reference coarse.toml --samples $samples --adaptive 0 "${flags[@]}" -o "$dir" ) > "$dir.log" 2>&1
  rc=$?
  set -e
  [ "$rc" -ne 0 ] || { cat "$dir.log"; fail "a run past the $kb kB file-size limit succeeded"; }
  [ "$rc" -lt 128 ] || { cat "$dir.log"; fail "the run died by signal $((rc - 128)) instead of failing with a message"; }
  grep -Eiq 'writ|disk|space|too large|input/output' "$dir.log" || { cat "$dir.log"; fail "no message about the failed write"; }
  check_whole "$dir"
  echo "full disk at $kb kB ($2): exit $rc: $(grep -m1 -A12 'kerf: error' "$dir.log" | grep -v '^#' | tr -s '\n ' ' ' | cut -c1-160)"
  "$kerf" reference coarse.toml --samples $samples --adaptive 0 "${flags[@]}" -o "$dir" --resume > "$dir.resume.log" 2>&1 \
    || { cat "$dir.resume.log"; fail "resume after the full disk"; }
  check_whole "$dir"
  diff <(physics whole/profile.csv) <(physics "$dir/profile.csv") || fail "the profile after a full disk and --resume differs"
  echo "  then --resume ($(grep -o -m1 'resuming after sample [0-9/]*\|no checkpoint' "$dir.resume.log")): the profile equals the uninterrupted one"
done

# 3b. A disk that fills between two checkpoints: a byte-exact file-size limit (set by Python's
#    resource module, SIGXFSZ ignored) just under the uninterrupted run's checkpoint after sample
#    10, which lets the checkpoint after sample 5 (five sample records fewer) through. The run fails
#    at sample 10 with a message; `--resume` continues from sample 5 and gives the profile.
ckpt10=$(stat -c %s whole/checkpoint.bin)
limit=$((ckpt10 - 256))
set +e
$py - "$limit" "$kerf" reference coarse.toml --samples $samples --adaptive 0 --no-fields -o full_ckpt > full_ckpt.log 2>&1 <<'PY'
import os, resource, signal, sys
limit = int(sys.argv[1])
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
os.execv(sys.argv[2], sys.argv[2:])
PY
rc=$?
set -e
[ "$rc" -ne 0 ] && [ "$rc" -lt 128 ] || { cat full_ckpt.log; fail "a run past the $limit-byte limit exited with $rc"; }
grep -q 'checkpoint' full_ckpt.log || { cat full_ckpt.log; fail "no message naming the checkpoint write"; }
check_whole full_ckpt
[ -e full_ckpt/checkpoint.bin ] && [ "$(stat -c %s full_ckpt/checkpoint.bin)" -le "$limit" ] \
  || fail "the checkpoint after sample 5 is not on disk whole"
"$kerf" reference coarse.toml --samples $samples --adaptive 0 --no-fields -o full_ckpt --resume > full_ckpt.resume.log 2>&1 \
  || { cat full_ckpt.resume.log; fail "resume after the disk filled between checkpoints"; }
grep -q "resuming after sample 5/$loads" full_ckpt.resume.log || { cat full_ckpt.resume.log; fail "did not resume from the checkpoint after sample 5"; }
check_whole full_ckpt
diff <(physics whole/profile.csv) <(physics full_ckpt/profile.csv) || fail "the profile after the disk filled and --resume differs"
echo "full disk between checkpoints ($limit-byte limit; checkpoint after sample 10 is $ckpt10 bytes): exit $rc: $(grep -m1 'checkpoint' full_ckpt.log | cut -c1-160)"
echo "  then --resume (resuming after sample 5/$loads): the profile equals the uninterrupted one"

# 4. An absurd load increment: the stylus jumps 2 m up (the block is 20 mm deep) between the two
#    samples solved.
sed 's/^to = \["20 mm", "0 mm", "28 mm"\]/to = ["20 mm", "0 mm", "2 m"]/' coarse.toml > absurd.toml
grep -q '"2 m"' absurd.toml || fail "clay_pull.toml has no pull target to exaggerate"
set +e
"$kerf" reference absurd.toml --samples 2 --adaptive 0 -o absurd > absurd.log 2>&1
rc=$?
set -e
[ "$rc" -lt 128 ] || { cat absurd.log; fail "the absurd increment crashed the run (signal $((rc - 128)))"; }
check_whole absurd
$py - absurd <<'PY' || { cat absurd.log; fail "absurd increment"; }
import json, math, os, re, sys
d = sys.argv[1]
m = json.load(open(os.path.join(d, "manifest.json")))
rows = [l.split(",") for l in open(os.path.join(d, "profile.csv")).read().splitlines()[1:]]
for r in rows:
    assert all(math.isfinite(float(v)) for i, v in enumerate(r) if i not in (1, 8)), r
if m.get("stopped"):
    # Stopped: the converged samples kept, the reason in the manifest, the last state saved.
    assert len(rows) == 1 and os.path.exists(os.path.join(d, "checkpoint.bin")), "stopped without the last state"
    assert "cut-backs" in m["stopped"], m["stopped"]
    print("absurd increment: stopped after %d converged sample(s), state saved: %s" % (len(rows), m["stopped"][:160]))
else:
    log = open(d + ".log").read()
    cut = [int(w) for w in re.findall(r"(\d+) cut-backs", log)]
    assert len(rows) == 2 and max(cut) > 0, "solved without a single cut-back: the increment was not absurd"
    print("absurd increment: converged with %d cut-backs" % sum(cut))
PY
echo "reference faults: all passed"
