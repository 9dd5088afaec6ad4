#!/usr/bin/python3
"""Plots of a kerf study (docs/studies.md), from kerf's own CSV files, with matplotlib.

  plot_study.py profiles OUT_STEM [LABEL=PROFILE.csv ...] [--run LABEL PROFILE.csv ...]
                 [--axis x|y|z|-x|-y|-z | --direction DX,DY,DZ]
                 [--reference LABEL REFERENCE.csv [--band-source TEXT]] [--time-panel] [--title TEXT]
      the resisting force along the direction of advance (an axis, or a blade's cutting direction
      d: -f . d) against tool travel along it ((p - p0) . d): the reference (a profile
      CSV with band_low, band_high columns [N]) in black with its uncertainty band in grey, one
      curve per fast model on top, the reference's interaction modes shaded where they occur
      (paper 001's deformation-1 / rupture / cutting / deformation-2; the legend lists those
      only); with --time-panel a force-time panel beside (a scene that holds or retreats). Writes
      OUT_STEM.png, OUT_STEM.pdf and OUT_STEM.csv, the data drawn: panel (travel [mm] or time [s]),
      series, x, y [N], band_low, band_high [N] (empty for the models).

  plot_study.py pareto OUT_STEM TABLE.csv --error COLUMN --cost COLUMN --label COLUMN
                 [--scene SCENE] [--floor VALUE] [--title TEXT]
      error against p99 cost per step for the rows of a study table (those of SCENE), log-log, one
      line per model through its resolutions ("MODEL [resolution]" rows), every point labelled,
      the reference uncertainty as a floor (errors below it mean nothing; rows "below reference
      uncertainty" sit on it), the 1 kHz and 10 kHz servo budgets (1 ms and 100 us) marked.
      Writes OUT_STEM.png, .pdf and OUT_STEM.csv (series, x, y, label).

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


def write_data(stem, header, rows):
    """The figure's data beside it, STEM.csv, written like the figure (beside its name, renamed)."""
    tmp = f"{stem}.tmp.{os.getpid()}.csv"
    with open(tmp, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(header)
        for r in rows:
            w.writerow(["" if v is None else (repr(v) if isinstance(v, float) else v) for v in r])
    os.replace(tmp, f"{stem}.csv")


def curves(rows, direction):
    """Per tool: (tool, times [s], travel [mm], resisting force [N], modes, source rows), along the
    unit vector `direction`."""
    out = []
    for tool in sorted({r["tool"] for r in rows}):
        mine = [r for r in rows if r["tool"] == tool]
        p0 = [float(mine[0]["p" + c]) for c in "xyz"]
        travel = [1e3 * sum(direction[i] * (float(r["p" + "xyz"[i]]) - p0[i]) for i in range(3)) for r in mine]  # mm
        # The body pushes back against the advance: plot the resisting force, -f . d.
        force = [-sum(direction[i] * float(r["f" + "xyz"[i]]) for i in range(3)) for r in mine]
        out.append((tool, [float(r["t"]) for r in mine], travel, force, [r["mode"] for r in mine], mine))
    return out


def shade_modes(ax, xs, ys, modes):
    """A broad translucent band under each stretch of the curve spent in one mode (stretches in time
    order, so a retreat is not confused with the advance over the same travel); returns the modes drawn."""
    drawn = []
    start = 0
    for k in range(1, len(modes) + 1):
        if k == len(modes) or modes[k] != modes[start]:
            colour = MODE_COLOURS.get(modes[start])
            if colour:
                stretch = slice(max(start - 1, 0), k)
                ax.plot(xs[stretch], ys[stretch], color=colour, lw=9, solid_capstyle="butt", zorder=1)
                if modes[start] not in drawn:
                    drawn.append(modes[start])
            start = k
    return drawn


def direction_of(axis=None, direction=None):
    """The unit direction of advance and its name for the axis label: an axis (x, -z, ...) or a
    vector "DX,DY,DZ" (normalised; named as its axis when it is one)."""
    if direction is None:
        index, sign = AXES[axis]
        return tuple(float(sign) if i == index else 0.0 for i in range(3)), axis
    try:
        v = [float(c) for c in direction.split(",")]
    except ValueError:
        v = []
    norm = math.sqrt(sum(c * c for c in v)) if len(v) == 3 else 0.0
    if not (norm > 0.0 and math.isfinite(norm)):
        sys.exit(f"--direction: expected three numbers DX,DY,DZ, not all zero, got {direction!r}")
    v = tuple(c / norm for c in v)
    for name, (index, sign) in AXES.items():
        if abs(v[index] - sign) < 1e-12:
            return v, name
    return v, "d = (" + ", ".join(f"{c:.3g}" for c in v) + ")"


def plot_profiles(stem, runs, axis, reference=None, band_source="", time_panel=False, title="", direction=None):
    """runs: [(label, path)] of the fast models; reference: (label, path) of the finest reference,
    its CSV a profile with band_low and band_high columns [N] (the resisting force's band, along
    the same direction); `direction` ("DX,DY,DZ") replaces the axis when given."""
    d, name_of_d = direction_of(axis, direction)
    panels = [("travel", f"tool travel along {name_of_d} [mm]")] + ([("time", "time [s]")] if time_panel else [])
    fig, axes = plt.subplots(1, len(panels), figsize=(7 * len(panels), 4.5), squeeze=False)
    axes = {name: ax for (name, _), ax in zip(panels, axes[0])}
    data = []
    modes_drawn = []
    series = ([(reference[0], reference[1], True)] if reference else []) + [(label, path, False) for label, path in runs]
    shaded = False
    for n, (label, path, is_reference) in enumerate(series):
        rows = read_profile(path)
        tools = curves(rows, d)
        for tool, times, travel, force, modes, source in tools:
            name = label if len(tools) == 1 else f"{label} ({tool})"
            low = high = None
            if is_reference:
                if "band_low" not in source[0] or "band_high" not in source[0]:
                    sys.exit(f"{path}: the reference needs band_low and band_high columns")
                low = [float(r["band_low"]) if r["band_low"] else math.nan for r in source]
                high = [float(r["band_high"]) if r["band_high"] else math.nan for r in source]
            for panel, ax in axes.items():
                xs = travel if panel == "travel" else times
                if not shaded:
                    # The modes of the ground truth (the reference, else the first run), where they occur.
                    for m in shade_modes(ax, xs, force, modes):
                        if m not in modes_drawn:
                            modes_drawn.append(m)
                if is_reference:
                    ax.fill_between(xs, low, high, color="0.6", alpha=0.35, lw=0, zorder=2,
                                    label=f"{name}: {band_source}" if band_source else f"{name}: band")
                    ax.plot(xs, force, color="black", lw=1.6, label=name, zorder=4)
                else:
                    ax.plot(xs, force, lw=1.1, label=name, zorder=3)
                for k in range(len(xs)):
                    data.append((panel, name, xs[k], force[k], low[k] if low else None, high[k] if high else None))
            shaded = True
    # The ground truth sets the scale: a model whose force runs beyond four times the reference's
    # extent (its band included) leaves the axes, and is named, with its largest force, at the top;
    # its whole curve stays in the data file.
    off_scale = []
    if reference:
        ref_values = [v for p_, name_, x_, y_, lo, hi in data if name_.startswith(reference[0])
                      for v in (y_, lo, hi) if v is not None and not math.isnan(v)]
        if ref_values:
            top = 4.0 * max(max(abs(v) for v in ref_values), 1e-12)
            peaks = {}
            for p_, name_, x_, y_, lo, hi in data:
                if not name_.startswith(reference[0]):
                    peaks[name_] = max(peaks.get(name_, 0.0), abs(y_))
            off_scale = sorted((name_, peak) for name_, peak in peaks.items() if peak > top)
            if off_scale:
                bottom = min(min(ref_values), 0.0)
                for ax in axes.values():
                    ax.set_ylim(bottom - 0.05 * (top - bottom), top)
                axes["travel"].text(0.99, 0.99, "off scale: " + ", ".join(f"{n_} (up to {pk:.3g} N)" for n_, pk in off_scale),
                                    transform=axes["travel"].transAxes, ha="right", va="top", fontsize=6, color="0.3")
    for panel, ax in axes.items():
        ax.set_xlabel(dict(panels)[panel])
        ax.set_ylabel("resisting force [N]")
        ax.grid(alpha=0.3)
    first = axes["travel"]
    legend1 = first.legend(loc="upper left", fontsize=7)
    if modes_drawn:
        first.add_artist(legend1)
        handles = [plt.Line2D([0], [0], color=MODE_COLOURS[m], lw=6) for m in modes_drawn]
        first.legend(handles, modes_drawn, loc="lower right", fontsize=7,
                     title="mode (reference)" if reference else "mode (first run)")
    if title:
        fig.suptitle(title)
    write_data(stem, ["panel", "series", "x", "y", "band_low", "band_high"],
               [(p, s, x, y, None if lo is None or math.isnan(lo) else lo, None if hi is None or math.isnan(hi) else hi)
                for p, s, x, y, lo, hi in data])
    save(fig, stem)


def plot_pareto(stem, table, error_column, cost_column, label_column, scene=None, floor=None, title=""):
    """Error against p99 cost, one line per model through its resolutions (rows "MODEL" or
    "MODEL [resolution]", in the table's order), every point labelled; a row whose error is below the
    reference uncertainty is drawn on the floor (a downward triangle)."""
    with open(table, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    series = {}
    for r in rows:
        if scene is not None and r.get("scene") != scene:
            continue
        label = r.get(label_column, "")
        if label.startswith("reference"):
            continue
        try:
            c = float(r[cost_column])
        except (KeyError, ValueError):
            continue
        below = r.get(error_column, "").startswith("below")
        if below:
            if floor is None:
                continue
            e = floor
        else:
            try:
                e = float(r[error_column])
            except (KeyError, ValueError):
                continue  # unmeasured cells are empty
        if not (c > 0 and math.isfinite(c) and e > 0 and math.isfinite(e)):
            continue
        base = label.split(" [", 1)[0]
        series.setdefault(base, []).append((c, e, label, below))
    if not series:
        sys.exit(f"{table}: no row{' of scene ' + scene if scene else ''} has both {error_column!r} and {cost_column!r}")
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    data = []
    every = [p for points in series.values() for p in points]
    for base, points in series.items():
        # In the table's order: a model's resolutions as the study lists them (ascending).
        line, = ax.plot([c for c, _, _, _ in points], [e for _, e, _, _ in points], marker="o", ms=4, lw=1.2, label=base)
        for c, e, label, below in points:
            if below:
                ax.scatter([c], [e], marker="v", s=40, color=line.get_color(), zorder=4)
            ax.annotate(label + (" (below ref.)" if below else ""), (c, e), fontsize=7, xytext=(3, 3),
                        textcoords="offset points")
            data.append((base, c, e, label + (" (below reference uncertainty)" if below else "")))
    unit_scale = 1e-6 if "[µs]" in cost_column or "[us]" in cost_column else 1.0
    ax.set_xscale("log")
    ax.set_yscale("log")
    for budget, name in ((1e-3, "1 kHz"), (1e-4, "10 kHz")):
        ax.axvline(budget / unit_scale, color="grey", ls="--", lw=1)
        ax.text(budget / unit_scale, 0.02, f" {name} budget", transform=ax.get_xaxis_transform(), rotation=90, fontsize=8,
                va="bottom", ha="right", color="0.35")
        data.append((f"budget {name}", budget / unit_scale, None, "servo period"))
    if floor is not None and floor > 0:
        low = min(floor, min(e for _, e, _, _ in every)) / 3
        ax.set_ylim(bottom=low)
        ax.axhspan(low, floor, color="0.88", zorder=0)
        ax.axhline(floor, color="0.4", lw=1, zorder=1, label="reference uncertainty")
        data.append(("reference uncertainty", None, floor, "errors below mean nothing"))
    ax.set_xlabel(cost_column)
    ax.set_ylabel(error_column)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="best")
    if title:
        ax.set_title(title)
    write_data(stem, ["series", "x", "y", "label"], data)
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
    p.add_argument("runs", nargs="*", help="LABEL=PROFILE.csv")
    p.add_argument("--axis", default="-z", choices=list(AXES))
    p.add_argument("--direction", help="the direction of advance DX,DY,DZ (e.g. a blade's cutting direction); replaces --axis")
    p.add_argument("--run", nargs=2, action="append", default=[], metavar=("LABEL", "PROFILE"),
                   help="a fast model's profile (a label may hold '=')")
    p.add_argument("--reference", nargs=2, metavar=("LABEL", "REFERENCE"),
                   help="the finest reference: a profile CSV with band_low, band_high [N]")
    p.add_argument("--band-source", default="", help="what the band is, for the legend")
    p.add_argument("--time-panel", action="store_true", help="force against time beside force against travel")
    p.add_argument("--title", default="")
    q = sub.add_parser("pareto")
    q.add_argument("stem")
    q.add_argument("table")
    q.add_argument("--error", required=True)
    q.add_argument("--cost", required=True)
    q.add_argument("--label", required=True)
    q.add_argument("--scene", help="only this scene's rows (column 'scene')")
    q.add_argument("--floor", type=float, help="the reference uncertainty, in the error column's unit")
    q.add_argument("--title", default="")
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
        runs += [tuple(r) for r in args.run]
        reference = tuple(args.reference) if args.reference else None
        plot_profiles(args.stem, runs, args.axis, reference, args.band_source, args.time_panel, args.title, args.direction)
    else:
        plot_pareto(args.stem, args.table, args.error, args.cost, args.label, args.scene, args.floor, args.title)


if __name__ == "__main__":
    main(sys.argv[1:])
