#!/usr/bin/env bash
# Cook's membrane, kerf against FEBio side by side on the same gmsh meshes (docs/reference.md,
# "kerf against FEBio"). For each element size H (default 8 4 2 1 mm) the mesh MESHES/cook_hH.msh
# (kerf) / .feb (FEBio, the same mesh as tet10) is solved by kerf's P2 reference
# (build/experiments/benchmarks/cook_febio solve) and by FEBio ($FEBIO), one thread each,
# alternately, REPEAT times, both in the same N equal load steps; the median CPU time (user + sys
# of the whole process, start-up included) and the tip displacement u_y(48, 52, 0.5) mm are paired.
# Ends with the headline, like for like:
#   same mesh, N equal load steps, both converged: kerf R× faster than FEBio (…)
# (R < 1: kerf is slower), where "converged" is checked, not assumed: on every mesh both tips must
# agree to 1e-5 of the tip (FEBio's log prints six significant digits), else the line says which
# did not. FEBio's default convergence test (dtol 1e-3 on the displacement increment, etol 1e-2 on
# the energy, no residual test) stops short of the equilibrium in few steps (in one step its 1 mm
# tip is 7e-3 mm short), so its copy of the .feb gets tighter tolerances (--febio-tol).
# A second line pairs each FEBio run with the cheapest kerf run at least as accurate (against the
# Richardson extrapolation of kerf's three finest meshes), whatever its mesh ("equal accuracy").
#
# The inputs are not committed: `cook_febio mesh H MESHES` writes them from
# experiments/benchmarks/cook/cook_membrane.geo (gmsh, through kerf) when missing or with --mesh.
#
# FEBio is built from its public source in a scratch folder, never committed. Without MKL it solves
# with its skyline solver (hence optimize_bw 1 in the inputs):
#   git clone https://github.com/febiosoftware/FEBio /tmp/febio-src      # v4.11 measured
#   cmake -S /tmp/febio-src -B /tmp/febio-build -DCMAKE_BUILD_TYPE=Release \
#         -DCMAKE_CXX_FLAGS="-include cstring" -DUSE_MKL=OFF -DUSE_HYPRE=OFF -DUSE_MMG=OFF -DUSE_LEVMAR=OFF \
#         -DCMAKE_EXE_LINKER_FLAGS=-fopenmp -DCMAKE_SHARED_LINKER_FLAGS=-fopenmp   # OpenMP at link without MKL
#   nice -n 19 make -C /tmp/febio-build -j2 febio4        # ~10 min on 2 idle cores
#   export FEBIO=/tmp/febio-build/bin/febio4
# With MKL (FEBio's PARDISO, its default solver; Debian 12's non-free section has MKL 2020.4): the
# static libraries unpacked from the .debs into a scratch folder, nothing installed (installing
# libmkl-rt would register MKL as the machine's BLAS/LAPACK):
#   (cd /tmp/mkl-debs && apt-get download libmkl-dev libmkl-interface-dev libmkl-threading-dev \
#        libmkl-computational-dev)   # from bookworm's non-free section, through a private apt sources list
#   for d in /tmp/mkl-debs/*.deb; do dpkg -x "$d" /tmp/mkl; done
#   cmake -S /tmp/febio-src -B /tmp/febio-build -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_FLAGS="-include cstring" \
#         -DUSE_MKL=ON -DMKL_INC=/tmp/mkl/usr/include/mkl -DMKL_LIB_DIR=/tmp/mkl/usr/lib/x86_64-linux-gnu \
#         -DMKL_OMP_LIB=/usr/lib/x86_64-linux-gnu/libiomp5.so -DUSE_HYPRE=OFF -DUSE_MMG=OFF -DUSE_LEVMAR=OFF
# Such a build solves with either: --febio-solver pardiso or skyline.
#
# Usage: experiments/benchmarks/febio_cook.sh [--mesh] [--repeat N] [--steps N] [--kerf "ARGS"]
#            [--febio-solver NAME] [--febio-tol "DTOL ETOL RTOL"] [H ...]
#   from the repository root, after `cmake --build build --target cook_febio`.
#   --steps N   both codes take N equal load steps (default 10, the .feb's; FEBio's copy of the
#               .feb is given time_steps N and step_size 1/N)
#   --kerf ARGS more options of `cook_febio solve` (default "--energy-line-search": FEBio's line
#               search, s(α) = du·R(u + α du), |s(α)| <= 0.9 |s(0)|)
#   --febio-solver NAME  FEBio's linear solver (default skyline; pardiso needs an MKL build)
#   --febio-tol "DTOL ETOL RTOL"  FEBio's convergence tolerances (default "1e-6 1e-6 0": the
#               displacement increment to 1e-6 of the displacement, the energy to 1e-6; "default"
#               keeps FEBio's own 1e-3 1e-2 0)
#   COOK_MESHES the inputs' folder (default build/experiments/benchmarks/cook)
set -euo pipefail
cd "$(dirname "$0")/../.."
KERF=${KERF_COOK:-build/experiments/benchmarks/cook_febio}
DIR=${COOK_MESHES:-build/experiments/benchmarks/cook}
REPEAT=3
MESH=0
STEPS=10
KERF_ARGS="--energy-line-search"
FEBIO_SOLVER=skyline
FEBIO_TOL="1e-6 1e-6 0"
SIZES=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --mesh) MESH=1 ;;
    --repeat) REPEAT=$2; shift ;;
    --steps) STEPS=$2; shift ;;
    --kerf) KERF_ARGS=$2; shift ;;
    --febio-solver) FEBIO_SOLVER=$2; shift ;;
    --febio-tol) FEBIO_TOL=$2; shift ;;
    *) SIZES+=("$1") ;;
  esac
  shift
done
[[ ${#SIZES[@]} -gt 0 ]] || SIZES=(8 4 2 1)
[[ -x $KERF ]] || { echo "febio_cook.sh: $KERF not built (cmake --build build --target cook_febio)" >&2; exit 1; }
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
SCRATCH=$(mktemp -d)
trap 'rm -rf "$SCRATCH"' EXIT

mkdir -p "$DIR"
for h in "${SIZES[@]}"; do
  if [[ $MESH == 1 || ! -f $DIR/cook_h$h.msh || ! -f $DIR/cook_h$h.feb ]]; then "$KERF" mesh "$h" "$DIR" >&2; fi
done

# FEBio's controls in its copy of the .feb: the load steps, the linear solver, the tolerances.
febio_controls() {
  local solver="      <linear_solver type=\"$FEBIO_SOLVER\"/>"
  if [[ $FEBIO_TOL != default ]]; then
    read -r dtol etol rtol <<< "$FEBIO_TOL"
    solver="$solver\n      <dtol>$dtol</dtol>\n      <etol>$etol</etol>\n      <rtol>$rtol</rtol>"
  fi
  sed -e "s#<time_steps>10</time_steps>#<time_steps>$STEPS</time_steps>#" \
      -e "s#<step_size>0.1</step_size>#<step_size>$(python3 -c "print(1 / $STEPS)")</step_size>#" \
      -e "s#      <qn_method type=\"BFGS\"/>#      <qn_method type=\"BFGS\"/>\n$solver#" "$1"
}

# cpu seconds (user + sys) of one command, its stdout in $SCRATCH/out
timed() { /usr/bin/time -f "%U %S" -o "$SCRATCH/time" "$@" > "$SCRATCH/out" 2> "$SCRATCH/err" || {
  cat "$SCRATCH/err" >&2; return 1; }; awk '{print $1 + $2}' "$SCRATCH/time"; }

RESULTS=$SCRATCH/results
: > "$RESULTS"
for h in "${SIZES[@]}"; do
  [[ -z ${FEBIO:-} ]] || febio_controls "$DIR/cook_h$h.feb" > "$SCRATCH/cook.feb"
  for ((k = 0; k < REPEAT; ++k)); do
    # shellcheck disable=SC2086 # KERF_ARGS is a list of options
    t=$(timed "$KERF" solve "$DIR/cook_h$h.msh" --steps "$STEPS" $KERF_ARGS)
    tip=$(sed -n 's/.*tip_mm=\([0-9.e+-]*\).*/\1/p' "$SCRATCH/out")
    dofs=$(sed -n 's/.*dofs=\([0-9]*\).*/\1/p' "$SCRATCH/out")
    echo "kerf $h $t $tip $dofs" >> "$RESULTS"
    if [[ -n ${FEBIO:-} ]]; then
      t=$( (cd "$SCRATCH" && timed "$FEBIO" -i cook.feb -silent) )
      # The log file's last data record ("Data = uy", then "<node>,<u_y>"): the last converged step.
      tip=$(awk '/Data = uy/ { getline; last = $0 } END { n = split(last, f, /[ ,]+/); print f[n] + 0 }' "$SCRATCH/cook.log")
      grep -q "N O R M A L   T E R M I N A T I O N" "$SCRATCH/cook.log" || tip=nan
      eqs=$(sed -n 's/.*N[umbe]*r of equations[ .]*: *\([0-9]*\).*/\1/p' "$SCRATCH/cook.log" | head -1)
      echo "febio $h $t $tip ${eqs:-?}" >> "$RESULTS"
    fi
  done
done

python3 - "$RESULTS" "$STEPS" "$KERF_ARGS" "$FEBIO_SOLVER" "$FEBIO_TOL" <<'EOF'
import math, statistics, sys
runs = {}
for line in open(sys.argv[1]):
    code, h, t, tip, size = line.split()
    runs.setdefault((code, float(h)), []).append((float(t), float(tip), size))
rows = {}
for (code, h), r in runs.items():
    rows[(code, h)] = (statistics.median(x[0] for x in r), r[0][1], r[0][2])
sizes = sorted({h for (_, h) in rows}, reverse=True)
steps = sys.argv[2]
kerf = [(h, *rows[("kerf", h)]) for h in sizes if ("kerf", h) in rows]
# Converged tip: Richardson extrapolation of kerf's three finest meshes (observed order p).
if len(kerf) >= 3:
    (_, _, a, _), (_, _, b, _), (_, _, c, _) = kerf[-3:]
    ratio = (a - b) / (b - c) if b != c else 0.0
    p = math.log(ratio, 2) if ratio > 1 else 2.0
    ref = c + (c - b) / (2 ** p - 1)
else:
    ref = kerf[-1][2] if kerf else float("nan")
print(f"Cook's membrane, P2 / tet10, {steps} load steps each, kerf solve {sys.argv[3]!r}, "
      f"FEBio {sys.argv[4]} with dtol etol rtol {sys.argv[5]!r}; converged tip {ref:.5f} mm (Richardson, kerf's finest three)")
print(f"{'H mm':>5} {'code':>6} {'DOFs/eqs':>9} {'tip mm':>10} {'error mm':>9} {'cpu s':>8}")
for h in sizes:
    for code in ("kerf", "febio"):
        if (code, h) in rows:
            t, tip, size = rows[(code, h)]
            print(f"{h:5g} {code:>6} {size:>9} {tip:10.5f} {abs(tip - ref):9.2e} {t:8.3f}")
febio = [(h, *rows[("febio", h)]) for h in sizes if ("febio", h) in rows]
if not febio:
    print("same mesh: FEBio not run (set FEBIO to its febio4 binary; see this script's header)")
    sys.exit(0)
def geo(v): return math.exp(sum(math.log(x) for x in v) / len(v))
# Like for like: the same mesh, the same load steps, and both answers converged — the two tips
# agree to 1e-5 of the tip (FEBio's log has six significant digits).
same, unconverged = [], []
for h, tf, tipf, _ in febio:
    if ("kerf", h) not in rows:
        continue
    tk = rows[("kerf", h)][1]
    if not abs(tipf - tk) <= 1e-5 * abs(tk):
        unconverged.append(f"{h:g} mm: FEBio {tipf:.5f} vs kerf {tk:.5f}")
    same.append((h, tf / rows[("kerf", h)][0]))
detail = ", ".join(f"{h:g} mm: {r:.2f}" for h, r in same)
if unconverged:
    print(f"same mesh, {steps} equal load steps, NOT both converged ({'; '.join(unconverged)}): "
          f"kerf {geo([r for _, r in same]):.2f}x faster than FEBio ({detail}; geometric mean; CPU seconds, one thread)")
else:
    print(f"same mesh, {steps} equal load steps, both converged: kerf {geo([r for _, r in same]):.2f}x faster than FEBio "
          f"({detail}; geometric mean; CPU seconds, one thread)")
equal = []
for h, tf, tipf, _ in febio:
    err = abs(tipf - ref)
    # Within 5 % of FEBio's error counts as equal.
    ok = [(t, hk) for hk, t, tip, _ in kerf if abs(tip - ref) <= 1.05 * err]
    if ok:
        t, hk = min(ok)
        equal.append((h, hk, tf / t))
if equal:
    detail = ", ".join(f"FEBio {h:g} mm vs kerf {hk:g} mm: {r:.2f}" for h, hk, r in equal)
    print(f"equal accuracy: kerf {geo([r for _, _, r in equal]):.2f}x faster than FEBio ({detail}; geometric mean; CPU seconds, one thread)")
else:
    print("equal accuracy: no kerf run as accurate as FEBio's")
EOF
