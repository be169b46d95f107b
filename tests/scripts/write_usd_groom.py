"""Writes a small BasisCurves groom with Pixar's usd-core (module `pxr`) as .usda, .usdc and
.usdz, and beside it `expected.json`: every strand's points in strandlight's world (Y up,
centimetres), computed by usd-core itself (ComputeLocalToWorldTransform, the stage's upAxis and
metersPerUnit), with the per-strand widths and per-point colours the reader must return.

The stage is deliberately awkward: Z up, millimetres (metersPerUnit 0.001), a parent Xform with
translate / rotateXYZ / uniform scale (so widths scale by one factor), a child Xform with an
orient quaternion about a pivot, a linear prim with per-curve (uniform) widths and per-vertex
displayColor, and a cubic catmullRom prim (pinned) with constant width, whose expected points
are the curve evaluated at its segment boundaries (usd-core's ComputeSegmentCounts checks how
many).

Usage: python3 write_usd_groom.py OUT_DIR [--strands N --points P]   (a benchmark groom: one
linear prim of N random-walk strands of P points, Y up, centimetres; no expected.json).
"""

import json
import math
import os
import sys

from pxr import Gf, Sdf, Usd, UsdGeom, UsdUtils, Vt

METERS_PER_UNIT = 0.001  # millimetres
TO_CENTIMETRES = METERS_PER_UNIT * 100.0


def linear_strands():
    """Strands of different lengths (2..6 points), bent so that no two points coincide."""
    strands = []
    for s in range(5):
        count = 2 + s
        x0, y0 = 10.0 * s, 3.0 * s - 4.0
        strands.append(
            [(x0 + 2.0 * math.sin(0.7 * i + s), y0 + 0.5 * i * i, 100.0 - 20.0 * i) for i in range(count)]
        )
    return strands


def catmull_rom_strands():
    return [
        [(-30.0, 5.0 * s, 90.0 - 15.0 * i + 3.0 * math.cos(1.3 * i + s)) for i in range(4 + s)]
        for s in range(3)
    ]


def catmull_rom_point(p0, p1, p2, p3, t):
    """USD's catmullRom basis (UsdGeomBasisCurves docs), written out independently of the reader."""
    t2, t3 = t * t, t * t * t
    w0 = -0.5 * t3 + t2 - 0.5 * t
    w1 = 1.5 * t3 - 2.5 * t2 + 1.0
    w2 = -1.5 * t3 + 2.0 * t2 + 0.5 * t
    w3 = 0.5 * t3 - 0.5 * t2
    return tuple(w0 * a + w1 * b + w2 * c + w3 * d for a, b, c, d in zip(p0, p1, p2, p3))


def pinned_catmull_rom_boundaries(points):
    """The curve at every segment boundary: pinned wrap adds a phantom point at each end
    (2·P0 − P1 and 2·Pn − Pn−1), so the curve starts at P0 and ends at Pn, one segment per gap."""
    p = [tuple(2 * a - b for a, b in zip(points[0], points[1]))] + list(points)
    p.append(tuple(2 * a - b for a, b in zip(points[-1], points[-2])))
    out = [catmull_rom_point(*p[0:4], 0.0)]
    for i in range(len(p) - 3):
        out.append(catmull_rom_point(*p[i : i + 4], 1.0))
    return out


def flat(strands):
    return [Gf.Vec3f(*p) for s in strands for p in s]


def write_stage(path):
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, METERS_PER_UNIT)
    world = UsdGeom.Xform.Define(stage, "/World")
    world.AddTranslateOp().Set(Gf.Vec3d(15.0, -7.0, 40.0))
    world.AddRotateXYZOp().Set(Gf.Vec3f(10.0, 25.0, -35.0))
    world.AddScaleOp().Set(Gf.Vec3f(1.5, 1.5, 1.5))
    head = UsdGeom.Xform.Define(stage, "/World/Head")
    head.AddTranslateOp(opSuffix="pivot").Set(Gf.Vec3d(0.0, 0.0, 50.0))
    head.AddOrientOp().Set(Gf.Quatf(math.cos(0.3), Gf.Vec3f(0.0, math.sin(0.3), 0.0)))
    head.AddTranslateOp(opSuffix="pivot", isInverseOp=True)
    stage.SetDefaultPrim(world.GetPrim())

    lin = linear_strands()
    hair = UsdGeom.BasisCurves.Define(stage, "/World/Head/Hair")
    hair.CreateTypeAttr(UsdGeom.Tokens.linear)
    hair.CreatePointsAttr(Vt.Vec3fArray(flat(lin)))
    hair.CreateCurveVertexCountsAttr(Vt.IntArray([len(s) for s in lin]))
    widths = [0.1 + 0.05 * s for s in range(len(lin))]
    hair.CreateWidthsAttr(Vt.FloatArray(widths))
    hair.SetWidthsInterpolation(UsdGeom.Tokens.uniform)
    colors = [Gf.Vec3f(0.1 * s, 0.05 * i, 0.3) for s, strand in enumerate(lin) for i in range(len(strand))]
    hair.CreateDisplayColorPrimvar(UsdGeom.Tokens.vertex).Set(Vt.Vec3fArray(colors))

    cr = catmull_rom_strands()
    curly = UsdGeom.BasisCurves.Define(stage, "/World/Curly")
    curly.CreateTypeAttr(UsdGeom.Tokens.cubic)
    curly.CreateBasisAttr(UsdGeom.Tokens.catmullRom)
    curly.CreateWrapAttr(UsdGeom.Tokens.pinned)
    curly.CreatePointsAttr(Vt.Vec3fArray(flat(cr)))
    curly.CreateCurveVertexCountsAttr(Vt.IntArray([len(s) for s in cr]))
    curly.CreateWidthsAttr(Vt.FloatArray([0.2]))
    curly.SetWidthsInterpolation(UsdGeom.Tokens.constant)
    stage.GetRootLayer().Save()
    return stage, lin, widths, colors, cr


def to_strandlight(stage, world_point):
    """The stage's world to strandlight's: Z up turned to Y up (front −Y to front +Z), then
    centimetres."""
    x, y, z = world_point
    if UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.z:
        x, y, z = x, z, -y
    k = UsdGeom.GetStageMetersPerUnit(stage) * 100.0
    return [k * x, k * y, k * z]


def expected(stage, lin, widths, colors, cr):
    time = Usd.TimeCode.Default()
    hair = UsdGeom.BasisCurves(stage.GetPrimAtPath("/World/Head/Hair"))
    curly = UsdGeom.BasisCurves(stage.GetPrimAtPath("/World/Curly"))
    m_hair = hair.ComputeLocalToWorldTransform(time)
    m_curly = curly.ComputeLocalToWorldTransform(time)
    # Widths scale with the transform's uniform scale (its determinant's cube root).
    s_hair = abs(m_hair.ExtractRotationMatrix().GetDeterminant()) ** (1.0 / 3.0)
    s_curly = abs(m_curly.ExtractRotationMatrix().GetDeterminant()) ** (1.0 / 3.0)
    strands = []
    color_index = 0
    for s, strand in enumerate(lin):
        points = [to_strandlight(stage, m_hair.Transform(Gf.Vec3d(*p))) for p in strand]
        strand_colors = [list(colors[color_index + i]) for i in range(len(strand))]
        color_index += len(strand)
        strands.append(
            {"points": points, "width": widths[s] * s_hair * TO_CENTIMETRES, "colors": strand_colors}
        )
    segments = curly.ComputeSegmentCounts(time)
    for s, strand in enumerate(cr):
        boundaries = pinned_catmull_rom_boundaries(strand)
        assert len(boundaries) == segments[s] + 1, (len(boundaries), segments[s])
        points = [to_strandlight(stage, m_curly.Transform(Gf.Vec3d(*p))) for p in boundaries]
        strands.append({"points": points, "width": 0.2 * s_curly * TO_CENTIMETRES, "colors": None})
    return {"strands": strands}


def write_benchmark(out_dir, n_strands, n_points):
    """A groom the size of a real one, for load timings: random-walk strands."""
    import random

    rng = random.Random(7)
    points, counts = [], []
    for _ in range(n_strands):
        x, y, z = rng.uniform(-10, 10), rng.uniform(0, 10), rng.uniform(-10, 10)
        for _ in range(n_points):
            points.append(Gf.Vec3f(x, y, z))
            x, y, z = x + rng.uniform(-0.2, 0.2), y - 0.3, z + rng.uniform(-0.2, 0.2)
        counts.append(n_points)
    for ext in ("usda", "usdc"):
        stage = Usd.Stage.CreateNew(os.path.join(out_dir, f"bench.{ext}"))
        UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
        UsdGeom.SetStageMetersPerUnit(stage, 0.01)
        curves = UsdGeom.BasisCurves.Define(stage, "/Hair")
        curves.CreateTypeAttr(UsdGeom.Tokens.linear)
        curves.CreatePointsAttr(Vt.Vec3fArray(points))
        curves.CreateCurveVertexCountsAttr(Vt.IntArray(counts))
        stage.GetRootLayer().Save()


def main():
    out_dir = sys.argv[1]
    os.makedirs(out_dir, exist_ok=True)
    if "--strands" in sys.argv:
        n = int(sys.argv[sys.argv.index("--strands") + 1])
        p = int(sys.argv[sys.argv.index("--points") + 1])
        write_benchmark(out_dir, n, p)
        return
    result = None
    for ext in ("usda", "usdc"):
        stage, *data = write_stage(os.path.join(out_dir, f"groom.{ext}"))
        result = expected(stage, *data)
    # A usdz holds the usdc as its first (root) layer.
    assert UsdUtils.CreateNewUsdzPackage(
        Sdf.AssetPath(os.path.join(out_dir, "groom.usdc")), os.path.join(out_dir, "groom.usdz")
    )
    with open(os.path.join(out_dir, "expected.json"), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
