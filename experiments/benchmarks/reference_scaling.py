#!/usr/bin/python3
"""Strong scaling of the reference's cut, measured (docs/reference.md, "Strong scaling of the cut").

Solves potato_rect_cut at the finest level of the full study (experiments/studies/full.toml: the
scene meshed at element size 1 mm, its crack path graded to 0.25 mm; the default study's finest is
2 mm: --element-size "2 mm"), as a study solves a level (experiments/study/reference_cache.cpp,
study_reference_settings: linear tetrahedra, the cohesive interface on (fracture auto), no fields,
the automatic linear solver) with 48 evenly spaced samples (the default study's count) and no
adaptive sampling, so that both runs solve the same loads, once on one process and once on N MPI processes (`--np N`, with `--solver direct`: MUMPS,
the distributed counterpart of the serial CHOLMOD/UMFPACK that the automatic choice takes there),
and prints, from each run's manifest.json:

  - the run's wall time (solver set-up and the solves) and the whole process's (mesh, start-up);
  - the solve time split into assembly, factorisation, solve (substitutions), communication
    (ghost exchange, the matrix's and vectors' exchange, reductions, waiting for the other
    processes) and the rest (line search updates, norms, constraints, commits), each process's
    own wall clock (rank 0's for the distributed run; SolverTimings in reference/finite_strain_solver.hpp);
  - the largest force difference to the serial profile, relative to the peak force;
  - the speed-up (serial wall / distributed wall) in one line.

Every process runs on one core: OMP_NUM_THREADS=1 and OPENBLAS_NUM_THREADS=1 for both runs (else the
serial run's BLAS would take the second core too). The load average of the machine before and after
each run is printed: numbers from a loaded machine are not speed results.

usage: reference_scaling.py KERF [--np 2] [--element-size "1 mm"] [--samples 48] [--until T]
                            [--solver direct] [--work DIR] [--reuse]
  --until T: only the samples up to t = T seconds (a shorter check of the script);
  --reuse:   tabulate the runs already in --work.
"""
import argparse
import csv
import json
import os
import shlex
import subprocess
import sys
import tempfile
import time


def run(kerf, args, processes, out):
    cmd = [kerf, "reference", "potato_rect_cut", "--element-size", args.element_size, "--samples", str(args.samples),
           "--adaptive", "0", "--no-fields", "-o", out]
    if args.until is not None:
        cmd += ["--until", str(args.until)]
    if processes > 1:
        cmd += ["--np", str(processes), "--solver", args.solver]
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    load_before = os.getloadavg()[0]
    wall = None
    if not (args.reuse and os.path.exists(os.path.join(out, "manifest.json"))):
        begin = time.monotonic()
        result = subprocess.run(cmd, capture_output=True, text=True, env=env)
        wall = time.monotonic() - begin
        with open(os.path.join(args.work, f"np{processes}.log"), "w") as log:
            log.write(result.stdout + result.stderr)
        if result.returncode != 0:
            sys.exit(f"failed ({result.returncode}): {shlex.join(cmd)}\n{result.stdout}\n{result.stderr}")
    load_after = os.getloadavg()[0]
    with open(os.path.join(out, "manifest.json")) as f:
        manifest = json.load(f)
    with open(os.path.join(out, "profile.csv")) as f:
        forces = [(float(r["fx"]), float(r["fy"]), float(r["fz"])) for r in csv.DictReader(f)]
    return {"cmd": shlex.join(cmd), "manifest": manifest, "forces": forces, "process_wall": wall,
            "load": (load_before, load_after)}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("kerf")
    parser.add_argument("--np", type=int, default=2)
    parser.add_argument("--element-size", default="1 mm")
    parser.add_argument("--samples", type=int, default=48)
    parser.add_argument("--until", type=float)
    parser.add_argument("--solver", default="direct")
    parser.add_argument("--work", default=tempfile.mkdtemp(prefix="kerf_reference_scaling_"))
    parser.add_argument("--reuse", action="store_true")
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    print(f"potato_rect_cut at {args.element_size}, {args.samples} samples"
          + (f" up to t = {args.until} s" if args.until is not None else "")
          + f"; {os.cpu_count()} cores; runs in {args.work}\n")
    runs = {p: run(args.kerf, args, p, os.path.join(args.work, f"np{p}")) for p in (1, args.np)}
    serial = runs[1]
    peak = max(max(abs(c) for c in f) for f in serial["forces"]) or 1.0
    print("| processes | DOFs | linear solver | Newton its | run wall s | process wall s | solve s | assembly | "
          "factorisation | solve | communication | rest | max |F - F_serial| / peak | load avg before, after |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for p, r in runs.items():
        m = r["manifest"]
        t = m["timings"]
        parts = t["solver_parts_s"]
        rest = t["solve_total_s"] - sum(parts.values())
        if len(r["forces"]) != len(serial["forces"]):
            sys.exit(f"np {p}: {len(r['forces'])} profile rows, the serial run has {len(serial['forces'])}")
        diff = max(max(abs(a - b) for a, b in zip(f, g)) for f, g in zip(r["forces"], serial["forces"])) / peak
        process_wall = f"{r['process_wall']:.1f}" if r["process_wall"] is not None else "-"
        print(f"| {m['solver']['mpi_processes']} | {m['solver']['dofs']} | {m['solver']['linear_solver']} | "
              f"{m['newton_iterations_total']} | {t['wall_s']:.1f} | {process_wall} | {t['solve_total_s']:.1f} | "
              f"{parts['assembly']:.1f} | {parts['factorization']:.1f} | {parts['solve']:.1f} | "
              f"{parts['communication']:.1f} | {rest:.1f} | {diff:.1e} | {r['load'][0]:.1f}, {r['load'][1]:.1f} |")
    for p, r in runs.items():
        print(f"<!-- np {p}: {r['cmd']} -->")
    speedup = serial["manifest"]["timings"]["wall_s"] / runs[args.np]["manifest"]["timings"]["wall_s"]
    print(f"\nspeed-up at np {args.np}: {speedup:.2f}x (run wall time, serial / distributed)")


if __name__ == "__main__":
    main()
