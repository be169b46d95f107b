#!/usr/bin/env python3
"""The table of docs/BENCHMARKS.md, "The view: layers", from scripts/view-error.sh's JSON lines.

Usage: scripts/view_error_table.py [out/view-error.jsonl]
Each cell: frame ms, relative RMSE against the truth with its noise removed, HDR-FLIP.
"""
import json
import sys

LOOKS = [
    ("opaque/volume", "opaque, volume (the old default)"),
    ("opaque/light-maps", "opaque, light maps"),
    ("layered/volume", "layered, volume (the default)"),
    ("layered/light-maps", "layered, light maps"),
    ("occupancy/light-maps", "occupancy, light maps"),
]


def main(path):
    rows = {}
    order = []
    for line in open(path):
        r = json.loads(line)
        key = (r["map"].split("/")[-1].rsplit(".", 1)[0], r["mode"])
        if key not in rows:
            rows[key] = {}
            order.append(key)
        rows[key][r["look"]] = r
    print("| map | mode | " + " | ".join(name for _, name in LOOKS) + " | truth noise, Mitsuba s |")
    print("|---|---|" + "---|" * len(LOOKS) + "---|")
    for key in order:
        cells = []
        for look, _ in LOOKS:
            r = rows[key].get(look)
            if r is None:
                cells.append("–")
                continue
            best = min(rows[key].values(), key=lambda x: x["rel_rmse_nc"])
            error = f"{r['rel_rmse_nc']:.3f}"
            if r is best:
                error = f"**{error}**"
            cells.append(f"{r['ms']:.0f} ms, {error} / {r['hdr_flip']:.3f}")
        any_row = next(iter(rows[key].values()))
        print(f"| {key[0]} | {key[1]} | " + " | ".join(cells)
              + f" | {any_row['truth_noise']:.3f}, {any_row['truth_seconds']:.0f} |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "out/view-error.jsonl")
