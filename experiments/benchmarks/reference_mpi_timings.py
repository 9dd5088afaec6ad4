#!/usr/bin/python3
"""Serial vs `mpirun -np 2` timings of the finite-strain reference (docs/reference.md).

Runs `kerf reference SCENE --samples N --no-fields` for P1/P2, a few global refinements, the
direct and the iterative linear solver, on 1 and 2 MPI processes, and prints a Markdown table
from each run's manifest.json: DOFs, Newton iterations, solve seconds per Newton iteration and
per load step (trajectory sample), wall seconds, peak resident memory of the largest process
(/usr/bin/time -v: with --np 2 kerf becomes mpirun, whose waited-for children are the ranks) and
the largest force difference to the serial direct run of the same case.

A load step is a trajectory sample that took Newton iterations (the first sample, at the
starting position, takes none and is not counted).

usage: reference_mpi_timings.py KERF [--scene clay_pull] [--samples 4] [--work DIR]
       [--cases P1r0,P1r1,P2r0] [--reuse]   (--reuse: tabulate the runs already in --work)
"""
import argparse
import csv
import json
import os
import re
import subprocess
import sys
import tempfile


def run(kerf, scene, samples, degree, refine, solver, np_, out, reuse):
    cmd = [kerf, "reference", scene, "--samples", str(samples), "--no-fields", "--degree", str(degree),
           "--refine", str(refine), "--solver", solver, "-o", out]
    if np_ > 1:
        cmd += ["--np", str(np_)]
    log = os.path.join(out, "time.log")
    if not (reuse and os.path.exists(os.path.join(out, "manifest.json"))):
        timed = ["/usr/bin/time", "-v", "-o", log + ".tmp"] + cmd
        result = subprocess.run(timed, capture_output=True, text=True)
        if result.returncode != 0:
            sys.exit(f"failed: {' '.join(cmd)}\n{result.stdout}\n{result.stderr}")
        os.replace(log + ".tmp", log)
    rss = None
    if os.path.exists(log):
        with open(log) as f:
            rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", f.read())
    with open(os.path.join(out, "manifest.json")) as f:
        manifest = json.load(f)
    with open(os.path.join(out, "profile.csv")) as f:
        forces = [(float(r["fx"]), float(r["fy"]), float(r["fz"])) for r in csv.DictReader(f)]
    return manifest, forces, int(rss.group(1)) / 1024.0 if rss else float("nan"), " ".join(cmd)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("kerf")
    parser.add_argument("--scene", default="clay_pull")
    parser.add_argument("--samples", type=int, default=4)
    parser.add_argument("--work", default=tempfile.mkdtemp(prefix="kerf_mpi_timings_"))
    parser.add_argument("--cases", default="P1r0,P1r1,P2r0")
    parser.add_argument("--reuse", action="store_true")
    args = parser.parse_args()
    print(f"{args.scene}, {args.samples} samples, --no-fields; per-iteration and per-step times are the "
          "solve time (assembly + linear solves + line search) from manifest.json.\n")
    print("| case | DOFs | solver | processes | Newton its | s / Newton it | s / load step | wall s | "
          "peak RSS MB | max |F − F_serial| / max |F| |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for case in args.cases.split(","):
        m = re.fullmatch(r"P([12])r(\d)", case)
        if not m:
            sys.exit(f"bad case {case} (want P<degree>r<refinements>)")
        degree, refine = int(m.group(1)), int(m.group(2))
        reference_forces = None
        for solver in ("direct", "iterative"):
            for np_ in (1, 2):
                out = os.path.join(args.work, f"{case}_{solver}_np{np_}")
                manifest, forces, rss, cmd = run(args.kerf, args.scene, args.samples, degree, refine, solver, np_, out,
                                              args.reuse)
                if reference_forces is None:
                    reference_forces = forces
                scale = max(max(abs(c) for c in f) for f in reference_forces) or 1.0
                diff = max(max(abs(a - b) for a, b in zip(f, g)) for f, g in zip(forces, reference_forces)) / scale
                its = manifest["newton_iterations_total"]
                solve = manifest["timings"]["solve_total_s"]
                steps = sum(1 for s in manifest["samples"] if s["newton_iterations"] > 0)
                wall = manifest["timings"]["wall_s"]
                print(f"| {case} | {manifest['solver']['dofs']} | {manifest['solver']['linear_solver']} | {np_} | "
                      f"{its} | {solve / max(its, 1):.3f} | {solve / max(steps, 1):.3f} | {wall:.1f} | "
                      f"{rss:.0f} | {diff:.1e} |", flush=True)
                print(f"<!-- {cmd} -->", file=sys.stderr)


if __name__ == "__main__":
    main()
