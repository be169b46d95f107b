"""Load-time benchmark of the USD and Alembic readers against `.hair` on a realistic groom.

Converts a Cem Yuksel `.hair` file (e.g. ../shared/data/hair/straight.hair) to USD (usda and
usdc, with usd-core) and Alembic (with PyAlembic): one linear BasisCurves prim / ICurves object
holding every strand, with per-point widths when the file has thickness. Then runs the
`load_timing` example of strandlight-runtime on the four files (median of N loads each).

Usage: python3 scripts/scene_groom_load_bench.py HAIR_FILE OUT_DIR [LOADS]
Needs `pip install usd-core alembic3d`; run from the repository root.
"""

import os
import struct
import subprocess
import sys

import imath
from alembic3d import Abc, AbcGeom
from pxr import Gf, Usd, UsdGeom, Vt


def read_hair(path):
    """Points, per-strand counts and per-point thickness (or None) of a .hair file."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:4] == b"HAIR", "not a .hair file"
    strands, points, flags, default_segments = struct.unpack_from("<4I", data, 4)
    default_thickness = struct.unpack_from("<f", data, 20)[0]
    at = 128
    if flags & 1:
        counts = [s + 1 for s in struct.unpack_from(f"<{strands}H", data, at)]
        at += 2 * strands
    else:
        counts = [default_segments + 1] * strands
    xyz = struct.unpack_from(f"<{3 * points}f", data, at)
    at += 12 * points
    if flags & 4:
        thickness = list(struct.unpack_from(f"<{points}f", data, at))
    else:
        thickness = [default_thickness] * points
    return [(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]) for i in range(points)], counts, thickness


def write_usd(path, points, counts, widths):
    stage = Usd.Stage.CreateNew(path)
    # .hair models are Z up in their own units (read as centimetres).
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    curves = UsdGeom.BasisCurves.Define(stage, "/Hair")
    curves.CreateTypeAttr(UsdGeom.Tokens.linear)
    curves.CreatePointsAttr(Vt.Vec3fArray([Gf.Vec3f(*p) for p in points]))
    curves.CreateCurveVertexCountsAttr(Vt.IntArray(counts))
    curves.CreateWidthsAttr(Vt.FloatArray(widths))
    curves.SetWidthsInterpolation(UsdGeom.Tokens.vertex)
    stage.GetRootLayer().Save()


def write_alembic(path, points, counts, widths):
    archive = Abc.OArchive(path)
    curves = AbcGeom.OCurves(archive.getTop(), "hair")
    positions = imath.V3fArray(len(points))
    for i, p in enumerate(points):
        positions[i] = imath.V3f(*p)
    n = imath.IntArray(len(counts))
    for k, c in enumerate(counts):
        n[k] = c
    w = imath.FloatArray(len(widths))
    for i, x in enumerate(widths):
        w[i] = x
    sample = AbcGeom.OCurvesSchemaSample(
        positions,
        n,
        AbcGeom.CurveType.kLinear,
        AbcGeom.CurvePeriodicity.kNonPeriodic,
        AbcGeom.OFloatGeomParamSample(w, AbcGeom.GeometryScope.kVertexScope),
    )
    curves.getSchema().set(sample)


def main():
    hair, out = sys.argv[1], sys.argv[2]
    loads = sys.argv[3] if len(sys.argv) > 3 else "5"
    os.makedirs(out, exist_ok=True)
    points, counts, widths = read_hair(hair)
    stem = os.path.splitext(os.path.basename(hair))[0]
    files = [hair]
    for ext in ("usda", "usdc"):
        files.append(os.path.join(out, f"{stem}.{ext}"))
        write_usd(files[-1], points, counts, widths)
    files.append(os.path.join(out, f"{stem}.abc"))
    write_alembic(files[-1], points, counts, widths)
    print(f"{len(counts)} strands, {len(points)} points", flush=True)
    subprocess.run(
        ["cargo", "run", "--release", "-q", "-p", "strandlight-runtime", "--example", "load_timing", "--", loads]
        + files,
        check=True,
    )


if __name__ == "__main__":
    main()
