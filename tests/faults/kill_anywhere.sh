#!/usr/bin/env bash
# Kill anywhere (docs/reliability.md, "Resume"): a command is SIGKILLed at KILLS random moments --
# while it starts and meshes, in a solve, while it writes a checkpoint, a profile or a table --
# and run again after each kill the way a user would (`kerf reference --resume`, `kerf study`
# into the same folder) until it finishes; its result must equal an uninterrupted run's.
#   reference: potato_wedge_cut with cohesive fracture (rupture, cutting, deformation-2) on a 5 mm
#              mesh, 16 samples, adaptive sampling off (checkpoints after samples 5, 10, 15): the profile, every column
#              but cost_s, to the last printed digit (the solver is deterministic);
#   study:     one scene (potato_wedge_cut), the fracture model, the reference on the default
#              study's level -1 mesh (4 mm) at 16 samples, the trajectory's vertices and adaptive
#              sampling (the default study solves 48 there; 16 keep every phase -- meshing, the
#              solve, a checkpoint, the cache, the table -- at a third of the time): the table
#              study.csv, every column but the compute costs.
# Kill times are uniform in [0, T] with T the uninterrupted run's wall time, from a fixed seed.
# A kill that lands after the run ended does not count; a run that ends is compared and the next
# one starts afresh, until KILLS kills have landed. After every kill, no file under a final name
# is half written (each is written beside it and renamed: meshes/atomic_file.hpp).
#
#   kill_anywhere.sh KERF reference|study WORK_DIR KILLS
set -euo pipefail
kerf="$1"
what="$2"
work="$3"
kills_wanted="$4"
source "$(dirname "${BASH_SOURCE[0]}")/fault_script_start.sh" "$work"

cat > tiny.toml <<'TOML'
[study]
name = "tiny"
scenes = ["potato_wedge_cut"]
models = ["fracture"]

[reference]
degree = 1
refinements = [-1]
samples = 16              # on the default study's L-1 mesh of the wedge (4 mm), the trajectory's vertices, adaptive
fracture = "auto"         # the blade opens the cohesive interface (without it the load path stops inside the potato)
time_verification = false # one solve
TOML

# run DIR [first]: one run of the command into DIR (resuming when not the first), in the background.
run() {
  local dir="$1" first="${2:-}"
  case "$what" in
    reference)
      local resume=(--resume)
      [ -n "$first" ] || [ ! -e "$dir/checkpoint.bin" ] && resume=()
      "$kerf" reference potato_wedge_cut --fracture on --element-size "5 mm" --samples 16 --adaptive 0 --no-fields -o "$dir" \
        "${resume[@]}" >> "$dir.log" 2>&1 &
      ;;
    study) "$kerf" study tiny.toml -j 1 -o "$dir" >> "$dir.log" 2>&1 & ;;
    *) fail "usage: kill_anywhere.sh KERF reference|study WORK_DIR KILLS" ;;
  esac
  pid=$!
}

# The result without its compute-cost columns, and a check that it is whole.
result() {
  local dir="$1"
  case "$what" in
    reference) $py - "$dir/profile.csv" <<'PY' ;;
import csv, sys
text = open(sys.argv[1]).read()
assert text.endswith("\n"), "no final newline"
rows = list(csv.reader(text.splitlines()))
assert rows[0] == "t,tool,px,py,pz,fx,fy,fz,mode,crack_extent,cost_s".split(","), rows[0]
for r in rows:
    assert len(r) == 11, r
    print(",".join(r[:10]))
PY
    study) $py - "$dir/study.csv" <<'PY' ;;
import csv, sys
text = open(sys.argv[1]).read()
assert text.endswith("\n"), "no final newline"
rows = list(csv.reader(text.splitlines()))
keep = [i for i, h in enumerate(rows[0]) if "cost" not in h and "rate allowed" not in h]
for r in rows:
    assert len(r) == len(rows[0]), r
    print(",".join(r[i] for i in keep))
PY
  esac
}

# After a kill: every final-named output that exists is whole.
check_whole() {
  $py - "$1" <<'PY' || fail "a half-written file in $1 after a kill"
import csv, glob, json, os, sys
d = sys.argv[1]
for f in [os.path.join(d, "profile.csv"), os.path.join(d, "study.csv")] + glob.glob(os.path.join(d, "**", "profile.csv"), recursive=True):
    if os.path.exists(f):
        text = open(f).read()
        assert text.endswith("\n"), f + ": no final newline"
        rows = list(csv.reader(text.splitlines()))
        assert all(len(r) == len(rows[0]) for r in rows), f + ": ragged rows"
for f in glob.glob(os.path.join(d, "**", "manifest.json"), recursive=True):
    json.load(open(f))
PY
}

# Uninterrupted.
start=$(date +%s.%N)
run whole first
wait "$pid" || { cat whole.log; fail "uninterrupted run"; }
T=$($py -c "import sys; print(max(0.5, float(sys.argv[2]) - float(sys.argv[1])))" "$start" "$(date +%s.%N)")
result whole > whole.txt || fail "the uninterrupted result is not whole"
echo "uninterrupted $what: $T s, $(($(wc -l < whole.txt) - 1)) rows"

RANDOM=2025
kills=0 finished=0 attempt=0 campaign=0
landed=()
dir=run0
first=1
while [ "$kills" -lt "$kills_wanted" ]; do
  attempt=$((attempt + 1))
  [ "$attempt" -le $((kills_wanted * 6)) ] || fail "only $kills kills landed in $attempt attempts"
  delay=$($py -c "import sys; print(float(sys.argv[1]) * int(sys.argv[2]) / 32767)" "$T" "$RANDOM")
  touch "$dir.log"
  lines=$(wc -l < "$dir.log")
  run "$dir" $first
  first=
  sleep "$delay"
  if kill -KILL "$pid" 2> /dev/null; then
    wait "$pid" 2> /dev/null || true
    kills=$((kills + 1))
    check_whole "$dir"
    # Where it landed: the last progress line this run printed.
    where=$(tail -n +$((lines + 1)) "$dir.log" | grep -Eo 'sample [0-9]+/[0-9]+|reference solve|wrote|resuming after sample [0-9]+' | tail -1 || true)
    landed+=("${where:-start}")
    continue
  fi
  # The run ended before the kill: it must have finished with the uninterrupted result.
  wait "$pid" || { cat "$dir.log"; fail "a run after a kill failed"; }
  result "$dir" > "$dir.txt" || fail "$dir: the result is not whole"
  diff whole.txt "$dir.txt" > /dev/null || { diff whole.txt "$dir.txt" | head; fail "$dir: the result differs from the uninterrupted one"; }
  finished=$((finished + 1))
  campaign=$((campaign + 1))
  dir=run$campaign
  first=1
done
# Finish the last run.
run "$dir" $first
wait "$pid" || { cat "$dir.log"; fail "the last run failed"; }
result "$dir" > "$dir.txt" || fail "$dir: the result is not whole"
diff whole.txt "$dir.txt" > /dev/null || { diff whole.txt "$dir.txt" | head; fail "$dir: the result differs from the uninterrupted one"; }
finished=$((finished + 1))
echo "$what: $kills kills landed in $attempt runs; $finished resumed runs finished, each equal to the uninterrupted one"
echo "the kills landed after (the run's last progress line): $(printf '%s\n' "${landed[@]}" | sort | uniq -c | tr -s ' \n' ' ')"
