#!/usr/bin/python3
"""Plots of a kerf study (issue 7), from kerf's own CSV files, with matplotlib.

  plot_study.py profiles OUT_STEM LABEL=PROFILE.csv [LABEL=PROFILE.csv ...] [--axis x|y|z|-x|-y|-z]
      force along the cutting axis against tool travel, one curve per run, the first run's
      interaction modes shaded (paper 001's deformation-1 / rupture / cutting / deformation-2);
      writes OUT_STEM.png and OUT_STEM.pdf.

  plot_study.py pareto OUT_STEM TABLE.csv --error COLUMN --cost COLUMN --label COLUMN
      error against cost per sample for every row of a study table, log-log, with the 1 kHz and
      10 kHz servo budgets (1 ms and 100 us per sample) marked; writes OUT_STEM.png and .pdf.

  plot_study.py stability OUT_STEM MODEL=STABILITY.csv [MODEL=STABILITY.csv ...]
      the stability map of `kerf stability`: one panel per swept axis, the axis value (factor on
      the nominal scene, or Poisson's ratio) across, one row per model, each run marked by its
      class (bounded / oscillating / diverged / NaN / refused); writes OUT_STEM.png and .pdf.

Files are written beside their final name and renamed, so a reader never sees half a plot.
"""
import argparse
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

MODE_COLOURS = {
    "deformation-1": "#dbe9f6",
    "rupture": "#f4b6b6",
    "cutting": "#f9e3b4",
    "deformation-2": "#d9f0d3",
}
AXES = {"x": (0, 1), "y": (1, 1), "z": (2, 1), "-x": (0, -1), "-y": (1, -1), "-z": (2, -1)}


def read_profile(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{path}: empty profile")
    return rows


def save(fig, stem):
    for ext in ("png", "pdf"):
        final = f"{stem}.{ext}"
        tmp = f"{stem}.tmp.{os.getpid()}.{ext}"
        fig.savefig(tmp, dpi=150, bbox_inches="tight")
        os.replace(tmp, final)
    plt.close(fig)


def plot_profiles(stem, runs, axis):
    index, sign = AXES[axis]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    first = True
    for label, path in runs:
        rows = read_profile(path)
        tools = sorted({r["tool"] for r in rows})
        for tool in tools:
            mine = [r for r in rows if r["tool"] == tool]
            p0 = float(mine[0]["p" + "xyz"[index]])
            travel = [1e3 * sign * (float(r["p" + "xyz"[index]]) - p0) for r in mine]  # mm
            # The body pushes back against the advance: plot the resisting force, -f . axis.
            force = [-sign * float(r["f" + "xyz"[index]]) for r in mine]
            if first:
                # Shade the first run's modes: a broad translucent band under each stretch of the
                # curve spent in one mode (stretches in time order, so a retreat is not confused
                # with the advance over the same travel).
                start = 0
                for k in range(1, len(mine) + 1):
                    if k == len(mine) or mine[k]["mode"] != mine[start]["mode"]:
                        colour = MODE_COLOURS.get(mine[start]["mode"])
                        if colour:
                            stretch = slice(max(start - 1, 0), k)
                            ax.plot(travel[stretch], force[stretch], color=colour, lw=9, solid_capstyle="butt",
                                    zorder=1)
                        start = k
                first = False
            name = label if len(tools) == 1 else f"{label} ({tool})"
            ax.plot(travel, force, label=name, lw=1.2, zorder=2)
    handles = [plt.Line2D([0], [0], color=c, lw=6) for c in MODE_COLOURS.values()]
    legend1 = ax.legend(loc="upper left", fontsize=8)
    ax.add_artist(legend1)
    ax.legend(handles, list(MODE_COLOURS), loc="lower right", fontsize=7, title="mode (first run)")
    ax.set_xlabel(f"tool travel along {axis} [mm]")
    ax.set_ylabel("resisting force [N]")
    ax.grid(alpha=0.3)
    save(fig, stem)


def plot_pareto(stem, table, error_column, cost_column, label_column):
    with open(table, newline="") as f:
        rows = list(csv.DictReader(f))
    points = []
    for r in rows:
        try:
            e, c = float(r[error_column]), float(r[cost_column])
        except (KeyError, ValueError):
            continue  # unmeasured cells are empty
        if e > 0 and c > 0 and math.isfinite(e) and math.isfinite(c):
            points.append((c, e, r.get(label_column, "")))
    if not points:
        sys.exit(f"{table}: no row has both {error_column!r} and {cost_column!r}")
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for c, e, label in points:
        ax.scatter([c], [e], s=25)
        ax.annotate(label, (c, e), fontsize=7, xytext=(3, 3), textcoords="offset points")
    unit_scale = 1e-6 if "[µs]" in cost_column or "[us]" in cost_column else 1.0
    for budget, name in ((1e-3, "1 kHz"), (1e-4, "10 kHz")):
        ax.axvline(budget / unit_scale, color="grey", ls="--", lw=1)
        ax.annotate(name, (budget / unit_scale, max(e for _, e, _ in points)), rotation=90, fontsize=8, va="top",
                    ha="right")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(cost_column)
    ax.set_ylabel(error_column)
    ax.grid(alpha=0.3, which="both")
    save(fig, stem)


STABILITY_STYLE = {
    "bounded": ("#2ca02c", "o"),
    "oscillating": ("#ff7f0e", "s"),
    "diverged": ("#d62728", "^"),
    "NaN": ("#000000", "X"),
    "refused": ("#7f7f7f", "D"),
}


def plot_stability(stem, runs):
    maps = []  # (model, rows)
    for model, path in runs:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
        if not rows or "axis" not in rows[0] or "outcome" not in rows[0]:
            sys.exit(f"{path}: not a kerf stability table (columns axis, value, outcome)")
        maps.append((model, rows))
    axes = []
    for _, rows in maps:
        for r in rows:
            if r["axis"] not in axes:
                axes.append(r["axis"])
    fig, panels = plt.subplots(1, len(axes), figsize=(2.6 * len(axes), 0.5 * len(maps) + 1.8), sharey=True,
                               squeeze=False)
    for panel, axis in zip(panels[0], axes):
        for y, (model, rows) in enumerate(maps):
            for r in rows:
                if r["axis"] != axis:
                    continue
                colour, marker = STABILITY_STYLE.get(r["outcome"], ("#1f77b4", "?"))
                panel.scatter([float(r["value"])], [y], c=colour, marker=marker, s=45, zorder=3)
        if axis != "poisson":
            panel.set_xscale("log")
            panel.axvline(1.0, color="grey", lw=0.8, ls=":")  # the nominal scene
            panel.set_xlabel("factor on nominal")
        else:
            panel.set_xlabel("Poisson's ratio")
        panel.set_title(axis, fontsize=9)
        panel.grid(alpha=0.3, which="both")
        panel.set_yticks(range(len(maps)))
        panel.set_yticklabels([m for m, _ in maps])
        panel.set_ylim(-0.6, len(maps) - 0.4)
    handles = [plt.Line2D([0], [0], color="w", marker=m, markerfacecolor=c, markersize=8, label=name)
               for name, (c, m) in STABILITY_STYLE.items()]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, bbox_to_anchor=(0.5, 1.0))
    save(fig, stem)


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="kind", required=True)
    p = sub.add_parser("profiles")
    p.add_argument("stem")
    p.add_argument("runs", nargs="+", help="LABEL=PROFILE.csv")
    p.add_argument("--axis", default="-z", choices=list(AXES))
    q = sub.add_parser("pareto")
    q.add_argument("stem")
    q.add_argument("table")
    q.add_argument("--error", required=True)
    q.add_argument("--cost", required=True)
    q.add_argument("--label", required=True)
    t = sub.add_parser("stability")
    t.add_argument("stem")
    t.add_argument("runs", nargs="+", help="MODEL=STABILITY.csv")
    args = parser.parse_args(argv)
    if args.kind == "stability":
        runs = []
        for item in args.runs:
            if "=" not in item:
                sys.exit(f"expected MODEL=STABILITY.csv, got {item!r}")
            runs.append(tuple(item.split("=", 1)))
        plot_stability(args.stem, runs)
    elif args.kind == "profiles":
        runs = []
        for item in args.runs:
            if "=" not in item:
                sys.exit(f"expected LABEL=PROFILE.csv, got {item!r}")
            label, path = item.split("=", 1)
            runs.append((label, path))
        plot_profiles(args.stem, runs, args.axis)
    else:
        plot_pareto(args.stem, args.table, args.error, args.cost, args.label)


if __name__ == "__main__":
    main(sys.argv[1:])
