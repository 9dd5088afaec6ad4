#!/usr/bin/env bash
# Every test's time limit (its ctest TIMEOUT) is at least 3x its measured time. Reads the times of
# the last runs from BUILD/Testing/Temporary/CTestCostData.txt (ctest's per-test average over
# the runs of that build folder) and the limits from `ctest --show-only=json-v1`; lists every test
# whose limit is under 3x its time, longest first, with the limit it needs. Run the whole suite on
# an idle machine first (`cd BUILD && ctest -j1`), then:
#   bash tests/timeouts_cover_3x.sh BUILD
# A test without a TIMEOUT property counts with DEFAULT seconds (ctest's own default: 1500).
set -euo pipefail
build=$1
default=${2:-1500}
costs="$build/Testing/Temporary/CTestCostData.txt"
[[ -f $costs ]] || { echo "$costs: no test times (run ctest in $build first)" >&2; exit 2; }
(cd "$build" && ctest --show-only=json-v1) | python3 -c '
import json, sys
default, costs = float(sys.argv[1]), sys.argv[2]
limit = {}
for t in json.load(sys.stdin)["tests"]:
    props = {p["name"]: p["value"] for p in t.get("properties", [])}
    limit[t["name"]] = float(props.get("TIMEOUT", default))
short = []
with open(costs) as f:
    for line in f:
        if line.startswith("---"):
            break
        name, runs, seconds = line.rsplit(None, 2)
        if name in limit and limit[name] < 3 * float(seconds):
            short.append((float(seconds), name))
for seconds, name in sorted(short, reverse=True):
    print(f"{name}: {seconds:.0f} s, TIMEOUT {limit[name]:.0f} s < 3x (needs >= {3 * seconds:.0f} s)")
print(f"{len(short)} of {len(limit)} tests with a TIMEOUT under 3x their time ({costs})")
sys.exit(1 if short else 0)
' "$default" "$costs"
