#!/usr/bin/python3
"""Figure 5 of Weatherley et al. (2010) in Basalt's terms: run time against compute ranks (workers) for the
four output stages (none; field saver; checkpoint every 100 steps; both), from a CSV of measurements.

CSV (one row per run; every repeat a row; the median per point is drawn), header required:
  compute_ranks            P, the ranks that step particles (the paper's workers)
  io_ranks                 Q, dedicated I/O ranks (0: the compute ranks write themselves)
  stage                    none | fields | checkpoint | both
  seconds_per_10000_steps  wall time of the stepping loop scaled to the paper's 10,000 steps
  geometry                 (optional) which packing; --geometry keeps one
Other columns are ignored. tools/bench/paper_study.py writes such a file (docs/data/paper_study/stages.csv).

  /usr/bin/python3 tools/bench/figure5.py docs/data/paper_study/stages.csv -o docs/img/figure5.png
"""
import argparse
import collections
import csv
import statistics
import sys

STAGES = [("none", "no output", "C0"), ("fields", "field saver (kinetic energy every step)", "C1"),
          ("checkpoint", "checkpoint every 100 steps", "C2"), ("both", "field saver + checkpoints", "C3")]
REQUIRED = ("compute_ranks", "io_ranks", "stage", "seconds_per_10000_steps")


def load(path, geometry):
    with open(path) as f:
        reader = csv.DictReader(f)
        missing = [c for c in REQUIRED if c not in (reader.fieldnames or [])]
        if missing:
            sys.exit(f"figure5: {path}: missing column(s) {', '.join(missing)} (need {', '.join(REQUIRED)})")
        points = collections.defaultdict(list)
        for line, row in enumerate(reader, start=2):
            if geometry and row.get("geometry") != geometry:
                continue
            stage = row["stage"]
            if stage not in {s for s, _, _ in STAGES}:
                sys.exit(f"figure5: {path}:{line}: unknown stage {stage!r} (none, fields, checkpoint, both)")
            try:
                key = (stage, int(row["io_ranks"]), int(row["compute_ranks"]))
                points[key].append(float(row["seconds_per_10000_steps"]))
            except ValueError as e:
                sys.exit(f"figure5: {path}:{line}: {e}")
    if not points:
        sys.exit(f"figure5: {path}: no measurements" + (f" for geometry {geometry!r}" if geometry else ""))
    return {k: statistics.median(v) for k, v in points.items()}, {k: len(v) for k, v in points.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("csv")
    ap.add_argument("-o", "--output", default="figure5.png")
    ap.add_argument("--geometry", help="keep only rows whose geometry column equals this")
    ap.add_argument("--title", default="Basalt, 15 mm cube per compute rank: run time by output stage")
    a = ap.parse_args()
    med, count = load(a.csv, a.geometry)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(12, 5.6))
    ranks = sorted({p for (_, _, p) in med})
    for stage, label, color in STAGES:
        for q, style, marker in ((0, "-", "o"), (1, "--", "s")):
            xs = [p for p in ranks if (stage, q, p) in med]
            if not xs:
                continue
            ys = [med[(stage, q, p)] for p in xs]
            ax.plot(xs, ys, style, marker=marker, color=color, label=f"{label}, Q = {q}")
            base = [med.get(("none", q, p)) for p in xs]
            if stage != "none" and all(base):
                ax2.plot(xs, [100 * (y / b - 1) for y, b in zip(ys, base)], style, marker=marker, color=color,
                         label=f"{label}, Q = {q}")
    ax.set_xlabel("compute ranks P (the paper's workers)")
    ax.set_ylabel("seconds per 10,000 steps (median)")
    ax.set_xticks(ranks)
    ax.set_ylim(bottom=0)
    ax.set_title(a.title, fontsize=10)
    ax2.axhline(0, color="grey", lw=0.5)
    ax2.set_xticks(ranks)
    ax2.set_xlabel("compute ranks P")
    ax2.set_ylabel("% over no output (same P and Q)")
    ax2.set_title("cost of output", fontsize=10)
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8)
    n = min(count.values())
    fig.text(0.01, 0.125, f"median of >= {n} runs per point; Q = I/O ranks (0: compute ranks write)", fontsize=8)
    fig.tight_layout(rect=(0, 0.14, 1, 1))
    fig.savefig(a.output, dpi=110)
    print("wrote", a.output)


if __name__ == "__main__":
    main()
