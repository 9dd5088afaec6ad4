#!/usr/bin/env bash
# Fault injection on `kerf study` (docs/reliability.md), through the command line: a
# small study (clay_pull and potato_wedge_cut, the spring network and fracture models, the
# reference at 4 and 48 samples on coarse meshes: two reference solves) is SIGKILLed half way, right
# after its first reference solve reached the cache. Then:
#   - no table (study.csv, study.md, study.tex) and no cached profile is half written under its
#     final name;
#   - the next run (same output folder) solves only the reference that was missing, taking the
#     other from the cache, and its table equals an uninterrupted run's (every column but the
#     compute costs; one timing run per model, --timing-runs 1, as the costs are not compared).
#
#   study_faults.sh KERF SCENES_DIR WORK_DIR
set -euo pipefail
kerf="$1"
scenes="$2"
work="$3"
source "$(dirname "${BASH_SOURCE[0]}")/fault_script_start.sh" "$work"

cat > faults.toml <<'TOML'
[study]
name = "faults"
description = "A study small enough to kill and resume in a test."
scenes = ["clay_pull", "potato_wedge_cut"]
models = ["springs", "fracture"]

[reference]
degree = 1
refinements = [0]
samples = 4
scene_samples = { potato_wedge_cut = 48 } # the default study's L-1 solve of the wedge (4 mm): on its
scene_refinements = { potato_wedge_cut = [-1] } # 8 mm level the crack front's saw-tooth (0.77 elements in the zone) makes the
                                                # adaptive inserts sensitive to the last digit of a solve
fracture = "auto" # the blades open the cohesive interface on the cut plane, as in the default study
time_verification = false # two solves, one per scene: the kill falls between them
TOML

# Every file under a final name is whole: tables end with a newline and have as many columns
# per row as their header (CSV) or are complete Markdown / LaTeX; cached profiles parse.
check_whole() {
  local dir="$1"
  $py - "$dir" <<'PY' || fail "a half-written file in $dir"
import csv, glob, os, sys
d = sys.argv[1]
for f in [os.path.join(d, "study.csv")] + glob.glob(os.path.join(d, "cache", "*", "profile.csv")):
    if not os.path.exists(f):
        continue
    text = open(f).read()
    assert text.endswith("\n"), f + ": no final newline"
    rows = list(csv.reader(text.splitlines()))
    assert len(rows) >= 2 and all(len(r) == len(rows[0]) for r in rows), f + ": ragged rows"
md = os.path.join(d, "study.md")
if os.path.exists(md):
    assert open(md).read().rstrip().endswith("|"), md + ": the table is cut"
tex = os.path.join(d, "study.tex")
if os.path.exists(tex):
    assert "\\end{tabular}" in open(tex).read(), tex + ": the table is cut"
PY
}

# The table without its cost columns (compute seconds differ from run to run).
physics() {
  $py - "$1" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
keep = [i for i, h in enumerate(rows[0]) if "cost" not in h and "rate allowed" not in h]
for r in rows:
    print(",".join(r[i] for i in keep))
PY
}

# Uninterrupted.
"$kerf" study faults.toml --timing-runs 1 -o whole > whole.log 2>&1 || { cat whole.log; fail "uninterrupted study"; }
grep -q '2 reference solve(s) run' whole.log || { cat whole.log; fail "the uninterrupted study did not solve 2 references"; }
check_whole whole

# Killed right after the first reference solve reached the cache.
"$kerf" study faults.toml --timing-runs 1 -o killed > killed.log 2>&1 &
pid=$!
for _ in $(seq 1 12000); do
  compgen -G "killed/cache/*/profile.csv" > /dev/null && break
  kill -0 "$pid" 2> /dev/null || break
  sleep 0.05
done
kill -9 "$pid" 2> /dev/null || fail "the study finished before it could be killed"
wait "$pid" 2> /dev/null || true
cached=$(compgen -G "killed/cache/*/profile.csv" | wc -l)
[ "$cached" -eq 1 ] || fail "expected one cached reference at the kill, found $cached"
[ ! -e killed/study.csv ] || fail "a table was written before the study ended"
check_whole killed
leftovers=$(find killed -name '*.tmp.*' | wc -l)
echo "killed half way: 1 of 2 references cached, no table, $leftovers temporary file(s) left beside final names"

# The next run takes the cached reference and solves the other.
"$kerf" study faults.toml --timing-runs 1 -o killed > resumed.log 2>&1 || { cat resumed.log; fail "the study after the kill"; }
grep -q '1 reference solve(s) run (the rest from the cache)' resumed.log \
  || { cat resumed.log; fail "the study after the kill did not resume from the cache"; }
check_whole killed
diff <(physics whole/study.csv) <(physics killed/study.csv) || fail "the resumed study's table differs"
echo "resumed: 1 reference solved, 1 from the cache; the table equals the uninterrupted one"
