#!/usr/bin/python3
"""Draws the benchmark commands' figures from the CSV files they write (matplotlib).

    plot.py quality  quality.csv OUT.png [--highlight LABEL]... [--about TEXT]
    plot.py growth   growth.csv  OUT.png [--about TEXT]
    plot.py sim      sim_rocking.csv OUTDIR [--about TEXT]

--about is the title's second line: what was measured where and when (the picture's size,
the device, the date), which the benchmarks pass; a figure redrawn by hand from an older
CSV gets it only if told.

The benchmarks call it themselves after writing their CSV; it can be rerun by hand on
any earlier CSV (to restyle a figure without measuring again). /usr/bin/python3 on
purpose: Debian's python3-matplotlib is installed for Debian's interpreter.
"""
import argparse
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")  # no display: write PNG files only
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import matplotlib.ticker  # noqa: E402


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return float("nan")


ABOUT = ""  # --about: the title's second line


def titled(ax, title):
    ax.set_title(title + ("\n" + ABOUT if ABOUT else ""), fontsize=11)


def finish(fig, ax, out):
    ax.grid(True, which="major", alpha=0.35)
    ax.grid(True, which="minor", alpha=0.12)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    print(f"wrote {out}")


def label_without_collisions(ax, points, first):
    """Names the points, most telling first (the marked pipelines, the Pareto front, then
    by error), skipping a label that would overlap one already placed; says how many
    went unnamed (they are in the CSV)."""
    import math
    xs = [math.log10(p[0]) for p in points]
    ys = [math.log10(p[1]) for p in points]
    span_x = (max(xs) - min(xs)) or 1.0
    span_y = (max(ys) - min(ys)) or 1.0
    order = sorted(range(len(points)),
                   key=lambda i: (points[i][2] not in first, not points[i][3], points[i][1]))
    placed, unnamed = [], 0
    for i in order:
        ms, err, label, _ = points[i]
        # A label's box, in fractions of the data range: ~1.1 % of the width a character.
        x0, y0 = (xs[i] - min(xs)) / span_x, (ys[i] - min(ys)) / span_y
        box = (x0, y0, x0 + 0.011 * len(label), y0 + 0.03)
        if any(box[0] < b[2] and b[0] < box[2] and box[1] < b[3] and b[1] < box[3] for b in placed):
            unnamed += 1
            continue
        placed.append(box)
        ax.annotate(label, (ms, err), textcoords="offset points", xytext=(4, 3), fontsize=6.5, color="0.2")
    if unnamed:
        ax.text(0.99, 0.01, f"{unnamed} points unnamed where labels would overlap (see the CSV)",
                transform=ax.transAxes, ha="right", va="bottom", fontsize=7, color="0.4")


def plot_quality(rows, out, highlights):
    """GPU ms against noise-corrected relMSE: every setting labelled, the Pareto front
    joined, the default and each --highlight pipeline marked and named in the legend."""
    points = []  # (ms, error, label, on_front)
    off_axis = []  # a corrected relMSE <= 0 is within the reference's noise: no place on a log axis
    for r in rows:
        ms, err = number(r["total_gpu_ms"]), number(r["rel_mse_corrected"])
        if not (ms > 0 and err > 0):
            off_axis.append(r["setting"])
            continue
        points.append((ms, err, r["setting"], r["pareto"] == "1"))
    if not points:
        sys.exit(f"plot.py: no setting has a positive time and corrected relMSE to plot")

    fig, ax = plt.subplots(figsize=(10, 6.5))
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.scatter([p[0] for p in points], [p[1] for p in points], s=18, color="0.6", label="settings", zorder=2)
    front = sorted((p for p in points if p[3]), key=lambda p: p[0])
    ax.plot([p[0] for p in front], [p[1] for p in front], "-o", color="tab:red", markersize=5, label="Pareto front",
            zorder=3)
    marked = ["default"] + [h for h in highlights if h != "default"]
    styles = ["*", "D", "s", "^", "v", "P", "X"]
    for i, name in enumerate(marked):
        hits = [p for p in points if p[2] == name]
        if hits:
            ax.scatter([p[0] for p in hits], [p[1] for p in hits], s=140 if i == 0 else 70, marker=styles[i % len(styles)],
                       color=plt.cm.tab10(i), edgecolor="black", linewidth=0.6, label=name, zorder=4)
    label_without_collisions(ax, points, marked)
    ax.set_xlabel("total GPU ms per frame")
    ax.set_ylabel("relative MSE less the reference's own noise (emitters masked)")
    titled(ax, "GPU time against error versus the path-traced reference")
    ax.legend(loc="best", fontsize=8, framealpha=0.9)
    if off_axis:
        print("not on the plot (corrected relMSE <= 0: within the reference's noise): " + ", ".join(off_axis))
        fig.text(0.01, 0.005, "within the reference's noise (not on the log axis): " + ", ".join(off_axis), fontsize=7)
    finish(fig, ax, out)


def plot_growth(rows, out):
    """Frame cost against the grown body count, one line per pipeline."""
    kind = next(k for k in rows[0].keys() if k not in ("pipeline",))  # the second column names what grew
    fig, ax = plt.subplots(figsize=(8, 5.5))
    ax.set_xscale("log")  # counts span decades; the cost axis is linear from 0, so heights compare
    ax.xaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
    for pipeline in dict.fromkeys(r["pipeline"] for r in rows):
        mine = [r for r in rows if r["pipeline"] == pipeline]
        xs = [max(number(r[kind]), 1) for r in mine]
        ys = [number(r["frame_ms"]) for r in mine]
        ax.plot(xs, ys, "-o", label=pipeline)
        for x, y, r in zip(xs, ys, mine):
            ax.annotate(f"{number(r['ratio']):.2f}×", (x, y), textcoords="offset points", xytext=(4, -10), fontsize=7)
    ax.set_ylim(bottom=0)
    ax.set_xlabel(kind)
    ax.set_ylabel("frame ms (wall, glFinish); labels: ratio to the first count")
    titled(ax, f"frame cost against {kind}, the scene moving")
    ax.legend(fontsize=8)
    finish(fig, ax, out)


def plot_sim(rows, outdir):
    """The tumbler's rocking error and energy drift against cost and against the sub-step."""
    figures = [("sim_time_vs_error.png", "us_per_sim_second", "microseconds per simulated second",
                "tumbler: time against error (exact rolling, RK4)"),
               ("sim_error_vs_dt.png", "substep_dt", "sub-step Δt (s)", "tumbler: error against the sub-step")]
    for name, xkey, xlabel, title in figures:
        fig, ax = plt.subplots(figsize=(8, 5.5))
        ax.set_xscale("log")
        ax.set_yscale("log")
        for sub in sorted({int(number(r["substeps"])) for r in rows}):
            mine = [r for r in rows if int(number(r["substeps"])) == sub]
            xs = [number(r[xkey]) for r in mine]
            for ykey, what, marker in (("period_error_10deg", "period error at 10°", "o"),
                                       ("period_error_60deg", "period error at 60°", "s"),
                                       ("energy_drift", "energy drift", "^")):
                pairs = [(x, number(r[ykey])) for x, r in zip(xs, mine) if number(r[ykey]) > 0]
                if pairs:
                    ax.plot(*zip(*pairs), "-" + marker, markersize=4, label=f"{what}, {sub} sub-step{'s' * (sub > 1)}")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("relative error")
        titled(ax, title)
        ax.legend(fontsize=8)
        finish(fig, ax, os.path.join(outdir, name))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("kind", choices=["quality", "growth", "sim"])
    parser.add_argument("csv")
    parser.add_argument("out", help="the PNG to write (for sim: the folder)")
    parser.add_argument("--highlight", action="append", default=[], help="quality: a setting to mark and name")
    parser.add_argument("--about", default="", help="the title's second line: size, device, date")
    args = parser.parse_args()
    global ABOUT
    ABOUT = args.about
    try:
        rows = read_rows(args.csv)
    except OSError as e:
        sys.exit(f"plot.py: {args.csv}: {e.strerror}")
    if not rows:
        sys.exit(f"plot.py: {args.csv}: no rows")
    try:
        if args.kind == "quality":
            plot_quality(rows, args.out, args.highlight)
        elif args.kind == "growth":
            plot_growth(rows, args.out)
        else:
            plot_sim(rows, args.out)
    except KeyError as e:
        sys.exit(f"plot.py: {args.csv}: no column {e} (a CSV from another command or version?)")


if __name__ == "__main__":
    main()
