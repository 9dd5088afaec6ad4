#!/usr/bin/env bash
# Cook's membrane, kerf against FEBio side by side on the same gmsh meshes (docs/reference.md,
# "Where the time goes"). For each element size H (default 8 4 2 1 mm) the mesh
# experiments/benchmarks/cook/cook_hH.msh (kerf) / .feb (FEBio, the same mesh as tet10) is solved by
# kerf's P2 reference (build/experiments/benchmarks/cook_febio solve) and by FEBio ($FEBIO), one
# thread each, alternately, REPEAT times; the median CPU time (user + sys of the whole process,
# start-up included) and the tip displacement u_y(48, 52, 0.5) mm are paired. Ends with
#   equal accuracy: kerf R× faster than FEBio (…)
#   same mesh: kerf R× faster than FEBio (…)
# (R < 1: kerf is slower). "Equal accuracy" pairs each FEBio run with the cheapest kerf run whose
# tip error is no larger (within 5 %); the error is against the Richardson extrapolation of kerf's three finest
# meshes. The .msh/.feb inputs are written by `cook_febio mesh H DIR` from
# experiments/benchmarks/cook/cook_membrane.geo (gmsh, through kerf); regenerate with --mesh.
#
# FEBio is built from its public source in a scratch folder, never committed:
#   git clone https://github.com/febiosoftware/FEBio /tmp/febio-src
#   cmake -S /tmp/febio-src -B /tmp/febio-build -DCMAKE_BUILD_TYPE=Release \
#         -DCMAKE_CXX_FLAGS="-include cstring" -DUSE_MKL=OFF -DUSE_HYPRE=OFF -DUSE_MMG=OFF -DUSE_LEVMAR=OFF \
#         -DCMAKE_EXE_LINKER_FLAGS=-fopenmp -DCMAKE_SHARED_LINKER_FLAGS=-fopenmp   # OpenMP at link without MKL
#   nice -n 19 make -C /tmp/febio-build -j2 febio4        # ~10 min on 2 idle cores
#   export FEBIO=/tmp/febio-build/bin/febio4
# Without MKL FEBio solves with its skyline solver (hence optimize_bw 1 in the inputs).
#
# Usage: experiments/benchmarks/febio_cook.sh [--mesh] [--repeat N] [--steps N] [--kerf "ARGS"] [H ...]
#   from the repository root, after `cmake --build build --target cook_febio`.
#   --steps N   both codes take N equal load steps (default 10, the .feb's; FEBio's copy of the
#               .feb is given time_steps N and step_size 1/N)
#   --kerf ARGS more options of `cook_febio solve` (default "--energy-line-search": FEBio's line
#               search, s(α) = du·R(u + α du), |s(α)| <= 0.9 |s(0)|)
set -euo pipefail
cd "$(dirname "$0")/../.."
KERF=${KERF_COOK:-build/experiments/benchmarks/cook_febio}
DIR=experiments/benchmarks/cook
REPEAT=3
MESH=0
STEPS=10
KERF_ARGS="--energy-line-search"
SIZES=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --mesh) MESH=1 ;;
    --repeat) REPEAT=$2; shift ;;
    --steps) STEPS=$2; shift ;;
    --kerf) KERF_ARGS=$2; shift ;;
    *) SIZES+=("$1") ;;
  esac
  shift
done
[[ ${#SIZES[@]} -gt 0 ]] || SIZES=(8 4 2 1)
[[ -x $KERF ]] || { echo "febio_cook.sh: $KERF not built (cmake --build build --target cook_febio)" >&2; exit 1; }
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1
SCRATCH=$(mktemp -d)
trap 'rm -rf "$SCRATCH"' EXIT

for h in "${SIZES[@]}"; do
  if [[ $MESH == 1 || ! -f $DIR/cook_h$h.msh || ! -f $DIR/cook_h$h.feb ]]; then "$KERF" mesh "$h" "$DIR" >&2; fi
done

# cpu seconds (user + sys) of one command, its stdout in $SCRATCH/out
timed() { /usr/bin/time -f "%U %S" -o "$SCRATCH/time" "$@" > "$SCRATCH/out" 2> "$SCRATCH/err" || {
  cat "$SCRATCH/err" >&2; return 1; }; awk '{print $1 + $2}' "$SCRATCH/time"; }

RESULTS=$SCRATCH/results
: > "$RESULTS"
for h in "${SIZES[@]}"; do
  for ((k = 0; k < REPEAT; ++k)); do
    # shellcheck disable=SC2086 # KERF_ARGS is a list of options
    t=$(timed "$KERF" solve "$DIR/cook_h$h.msh" --steps "$STEPS" $KERF_ARGS)
    tip=$(sed -n 's/.*tip_mm=\([0-9.e+-]*\).*/\1/p' "$SCRATCH/out")
    dofs=$(sed -n 's/.*dofs=\([0-9]*\).*/\1/p' "$SCRATCH/out")
    echo "kerf $h $t $tip $dofs" >> "$RESULTS"
    if [[ -n ${FEBIO:-} ]]; then
      sed -e "s#<time_steps>10</time_steps>#<time_steps>$STEPS</time_steps>#" \
          -e "s#<step_size>0.1</step_size>#<step_size>$(python3 -c "print(1 / $STEPS)")</step_size>#" \
          "$DIR/cook_h$h.feb" > "$SCRATCH/cook.feb"
      t=$( (cd "$SCRATCH" && timed "$FEBIO" -i cook.feb -silent) )
      # The log file's last data record ("Data = uy", then "<node>,<u_y>"): the last converged step.
      tip=$(awk '/Data = uy/ { getline; last = $0 } END { n = split(last, f, /[ ,]+/); print f[n] + 0 }' "$SCRATCH/cook.log")
      eqs=$(sed -n 's/.*N[umbe]*r of equations[ .]*: *\([0-9]*\).*/\1/p' "$SCRATCH/cook.log" | head -1)
      echo "febio $h $t $tip ${eqs:-?}" >> "$RESULTS"
    fi
  done
done

python3 - "$RESULTS" "$STEPS" "$KERF_ARGS" <<'EOF'
import math, statistics, sys
runs = {}
for line in open(sys.argv[1]):
    code, h, t, tip, size = line.split()
    runs.setdefault((code, float(h)), []).append((float(t), float(tip), size))
rows = {}
for (code, h), r in runs.items():
    rows[(code, h)] = (statistics.median(x[0] for x in r), r[0][1], r[0][2])
sizes = sorted({h for (_, h) in rows}, reverse=True)
kerf = [(h, *rows[("kerf", h)]) for h in sizes if ("kerf", h) in rows]
# Converged tip: Richardson extrapolation of kerf's three finest meshes (observed order p).
if len(kerf) >= 3:
    (_, _, a, _), (_, _, b, _), (_, _, c, _) = kerf[-3:]
    ratio = (a - b) / (b - c) if b != c else 0.0
    p = math.log(ratio, 2) if ratio > 1 else 2.0
    ref = c + (c - b) / (2 ** p - 1)
else:
    ref = kerf[-1][2] if kerf else float("nan")
print(f"Cook's membrane, P2 / tet10, {sys.argv[2]} load steps, kerf solve {sys.argv[3]!r}, converged tip {ref:.5f} mm (Richardson, kerf's finest three)")
print(f"{'H mm':>5} {'code':>6} {'DOFs/eqs':>9} {'tip mm':>10} {'error mm':>9} {'cpu s':>8}")
for h in sizes:
    for code in ("kerf", "febio"):
        if (code, h) in rows:
            t, tip, size = rows[(code, h)]
            print(f"{h:5g} {code:>6} {size:>9} {tip:10.5f} {abs(tip - ref):9.2e} {t:8.3f}")
febio = [(h, *rows[("febio", h)]) for h in sizes if ("febio", h) in rows]
if not febio:
    print("equal accuracy: FEBio not run (set FEBIO to its febio4 binary; see this script's header)")
    print("same mesh: FEBio not run")
    sys.exit(0)
same, equal = [], []
for h, tf, tipf, _ in febio:
    if ("kerf", h) in rows:
        same.append((h, tf / rows[("kerf", h)][0]))
    err = abs(tipf - ref)
    # Within 5 % of FEBio's error counts as equal (FEBio's looser convergence test moves its tip by
    # ~1e-4 mm on the same discretisation).
    ok = [(t, hk) for hk, t, tip, _ in kerf if abs(tip - ref) <= 1.05 * err]
    if ok:
        t, hk = min(ok)
        equal.append((h, hk, tf / t))
def geo(v): return math.exp(sum(math.log(x) for x in v) / len(v))
if equal:
    detail = ", ".join(f"FEBio {h:g} mm vs kerf {hk:g} mm: {r:.2f}" for h, hk, r in equal)
    print(f"equal accuracy: kerf {geo([r for _, _, r in equal]):.2f}x faster than FEBio ({detail}; geometric mean; CPU seconds, one thread)")
else:
    print("equal accuracy: no kerf run as accurate as FEBio's")
detail = ", ".join(f"{h:g} mm: {r:.2f}" for h, r in same)
print(f"same mesh: kerf {geo([r for _, r in same]):.2f}x faster than FEBio ({detail}; geometric mean; CPU seconds, one thread)")
EOF
