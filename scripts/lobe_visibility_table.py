#!/usr/bin/env python3
"""Lobe visibility against the path-traced ground truth: the table of docs/BENCHMARKS.md,
"Lobe visibility", from `compare --json` runs of both estimators (scripts/lobe-visibility.sh)
and the median-cut fronts of the saved truth bench (docs/bench-truth/runs/MAP.json).

usage: lobe_visibility_table.py RUN_DIR
"""
import json
import math
import sys
from pathlib import Path

MAPS = ["hdr_overcast_soil_puresky_1k", "quarry_01_1k", "photo_studio_01_1k", "moonless_golf_1k",
        "royal_esplanade_1k", "spruit_sunrise_1k", "venice_sunset_1k", "piz_compressed"]
EXT = {"piz_compressed": ".exr"}


def median_cut_ms_at(points, error, key):
    """ms of median cut's front at `error` (log-log between the counts around it), or None."""
    curve = sorted(((key(p), p["ms"]) for p in points), key=lambda c: -c[0])
    if curve and curve[0][0] <= error:
        return curve[0][1]
    for (e0, t0), (e1, t1) in zip(curve, curve[1:]):
        if e1 <= error <= e0:
            f = (math.log(error) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    return None


def speedup(points, error, ms, key):
    mc = median_cut_ms_at(points, error, key)
    if mc is None:
        slowest = max(points, key=lambda p: p["ms"])
        return f"> {slowest['ms'] / ms:.1f}×"
    return f"{mc / ms:.1f}×"


def main():
    runs = Path(sys.argv[1])
    rows = []
    for m in MAPS:
        name = m + EXT.get(m, ".hdr")
        saved = json.loads((Path("docs/bench-truth/runs") / f"{m}.json").read_text())
        front = {r["mode"]: [p for p in r["points"] if p["family"] == "median cut"]
                 for r in saved["env_lit"]}
        out = {v: json.loads((runs / f"{name}-{v}.json").read_text())
               for v in ["light-maps", "volume"]}
        for mode in ["single", "full"]:
            cells = [m, mode]
            for v in ["light-maps", "volume"]:
                r = out[v][mode]
                t = r["ground_truth"]["srbf"]
                ms = r["srbf"]["ms"]
                rmse_key = lambda p: p["truth"]["relative_rmse"]
                flip_key = lambda p: p["truth"]["hdr_flip"]
                cells += [f"{ms:.0f}", f"{t['relative_rmse_noise_corrected']:.4f} / {t['hdr_flip']:.4f}",
                          f"{r['srbf']['relative_rmse']:.4f}",
                          speedup(front[mode], t["relative_rmse"], ms, rmse_key) + " / "
                          + speedup(front[mode], t["hdr_flip"], ms, flip_key)]
            rows.append(cells)
    print("| map | mode | light maps: ms | vs truth: rel. RMSE (n.c.) / HDR-FLIP | vs DOM ref | × median cut (RMSE / FLIP) "
          "| volume: ms | vs truth: rel. RMSE (n.c.) / HDR-FLIP | vs DOM ref | × median cut (RMSE / FLIP) |")
    print("|---|---|---:|---|---:|---|---:|---|---:|---|")
    for c in rows:
        print("| " + " | ".join(c) + " |")


main()
