#!/bin/bash
# `kerf reference potato_rect_cut --np 2` against the serial run, as a user runs both: the cut with
# the cohesive interface on (fracture auto), on the scene meshed at 4 mm (its crack path graded to
# 1 mm), the blade from the approach to 3 mm deep, through rupture into the cut. The second method
# (the mesh distributed over two MPI processes, MUMPS) must reproduce the first (one process,
# CHOLMOD/UMFPACK): both stop at |R_free| <= 1e-9 (|f_int| + |f_ext|) and differ in round-off, so
# every force agrees to 1e-6 of the peak force (a face pair counted twice or lost, or a history
# not kept across the partition, shows at the 1e-2 level); the interaction modes are the same and
# the crack extents agree to 1 nm.
#
# usage: reference_cut_np2.sh KERF WORK
set -euo pipefail
kerf=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
args=(reference potato_rect_cut --element-size "4 mm" --until 3.6 --samples 7 --adaptive 0 --no-fields)
for run in serial np2; do
  extra=()
  [ "$run" = np2 ] && extra=(--np 2)
  if ! "$kerf" "${args[@]}" "${extra[@]}" -o "$work/$run" >"$work/$run.log" 2>&1; then
    echo "kerf ${args[*]} ${extra[*]} failed:"
    cat "$work/$run.log"
    exit 1
  fi
done
grep -q '"mpi_processes": 2' "$work/np2/manifest.json" || { echo "np2/manifest.json does not record 2 processes"; exit 1; }
grep -q '"interface_triangles": [1-9]' "$work/np2/manifest.json" || { echo "np2 ran without the cohesive interface"; exit 1; }
# profile.csv: t,tool,x,y,z,fx,fy,fz,mode,crack_extent,cost_s
awk -F, '
  FNR == 1 { next }
  FNR == NR { n++; f[n] = $6 " " $7 " " $8; mode[n] = $9; crack[n] = $10;
              m = sqrt($6 * $6 + $7 * $7 + $8 * $8); if (m > peak) peak = m; next }
  { k++; split(f[k], a, " ");
    d = sqrt(($6 - a[1]) ^ 2 + ($7 - a[2]) ^ 2 + ($8 - a[3]) ^ 2); if (d > worst) worst = d;
    if ($9 != mode[k]) { printf "row %d: mode %s, serial %s\n", k, $9, mode[k]; bad = 1 }
    c = $10 - crack[k]; if (c < 0) c = -c; if (c > 1e-9) { printf "row %d: crack extent %s, serial %s\n", k, $10, crack[k]; bad = 1 }
    if ($9 == "cutting") cut = 1 }
  END {
    if (k != n || n == 0) { printf "np2 has %d rows, serial %d\n", k, n; exit 1 }
    printf "%d rows, peak |F| %.6g N, max |F_np2 - F_serial| = %.3g N = %.3g of the peak\n", n, peak, worst, worst / peak
    if (!cut) { print "the blade never cut (no row in mode cutting)"; exit 1 }
    if (bad || worst > 1e-6 * peak) exit 1 }' "$work/serial/profile.csv" "$work/np2/profile.csv"
