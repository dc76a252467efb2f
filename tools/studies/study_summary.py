#!/usr/bin/env python3
"""A compact markdown table of a finished basalt-study (its study.json) for docs/accuracy.md: short names for
the quantities, each setting's relative error with its multiple of the ensemble's spread ("in" when inside it),
and its speed-up against the reference.

    /usr/bin/python3 tools/studies/study_summary.py OUT/study.json --names peak,t_peak,slope50 [--keys a,b]
"""
import argparse
import json


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("study", help="a study's study.json")
    ap.add_argument("--names", required=True, help="short names of the quantities, in the study's order")
    ap.add_argument("--keys", help="only these runs (comma-separated keys), in this order")
    a = ap.parse_args()
    with open(a.study) as f:
        d = json.load(f)
    specs = list(d["spread"])
    names = a.names.split(",")
    if len(names) != len(specs):
        raise SystemExit(f"{len(specs)} quantities in {a.study}, {len(names)} names given")
    runs = {r["key"]: r for r in d["runs"]}
    keys = a.keys.split(",") if a.keys else list(runs)
    ref = runs["reference"]
    axes = [k for k in ("rate", "damping") if any(r["setting"].get(k, 1.0) != 1 for r in runs.values())]
    print("| | " + " | ".join(f"`{n}`" for n in names) + " |")
    print("| --- |" + " ---: |" * len(names))
    print("| reference | " + " | ".join(f"{ref['quantities'][s]:.5g}" for s in specs) + " |")
    print("| spread (relative) | " + " | ".join(
        f"{d['spread'][s] / abs(ref['quantities'][s]) if ref['quantities'][s] else d['spread'][s]:.2g}"
        for s in specs) + " |")
    print()
    head = ["run", "precision", "dt fraction"] + axes + ["steps"] + names + ["speed-up"]
    print("| " + " | ".join(head) + " |")
    print("|" + " --- |" * 3 + " ---: |" * (len(head) - 3))
    for k in keys:
        r = runs[k]
        s = r["setting"]
        cells = [k, s.get("precision") or "-", f"{s['dt_fraction']:g}" if s.get("dt_fraction") else "-"]
        cells += [f"{s.get(x, 1.0):g}" for x in axes]
        if r["status"] != "ok":
            msg = r["message"].split(": error: ")[-1].split("scene.toml: ")[-1]
            msg = msg if len(msg) < 90 else msg[:87] + "..."
            print("| " + " | ".join(cells) + f" | {msg.replace('|', '/')} |" + " |" * len(names))
            continue
        errs = []
        for q in specs:
            e, n = r["errors"][q], r["noise"][q]
            errs.append(f"{e:.1e} ({'in' if n <= 1 else f'{n:.2g}x'})")
        print("| " + " | ".join(cells + [str(r["steps"])] + errs + [f"{r['speedup']:.2f}"]) + " |")


if __name__ == "__main__":
    main()
