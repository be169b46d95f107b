"""Writes a small ICurves groom with PyAlembic (PyPI `alembic3d`, modules `alembic3d`, `imath`)
as an Ogawa archive, and beside it `expected.json`: every strand's points in world space,
computed by Alembic itself (each parent IXform's sample matrix, composed up to the root the way
AbcGeom does: inherits honoured), with the per-strand widths the reader must return.

Alembic has no units or up axis: the points are the file's, unchanged.

The hierarchy is deliberately awkward: a parent xform with translate / rotate (axis-angle) /
uniform scale, a child xform with a full matrix, a linear curves object with per-curve widths,
and a second curves object under an xform with `inherits` off (so the parent's transform must
not apply).

Usage: python3 write_alembic_groom.py OUT_DIR [--from-usd FILE.usdc]   (the latter writes
`bench.abc` with the linear curves of a benchmark stage: a groom the size of a real one), or
with --bad-counts, --nan-point or --no-curves a damaged `groom.abc` (no expected.json).
"""

import json
import math
import os
import sys

import imath
from alembic3d import Abc, AbcGeom


def strands_a():
    return [
        [(1.0 * s + 0.3 * math.sin(i + s), 10.0 - 1.5 * i, 0.2 * i * i - s) for i in range(3 + s)]
        for s in range(4)
    ]


def strands_b():
    return [[(-5.0, 2.0 * s + 0.1 * i * i, -1.0 * i) for i in range(2 + 2 * s)] for s in range(3)]


def write_curves(parent, name, strands, widths, damage=None):
    curves = AbcGeom.OCurves(parent, name)
    positions = imath.V3fArray(sum(len(s) for s in strands))
    i = 0
    for s in strands:
        for p in s:
            positions[i] = imath.V3f(*p)
            i += 1
    counts = imath.IntArray(len(strands))
    for k, s in enumerate(strands):
        counts[k] = len(s)
    if damage == "--bad-counts":
        counts[0] += 1  # the counts sum to one more than the points
    if damage == "--nan-point":
        positions[1] = imath.V3f(0.0, float("nan"), 0.0)
    width_values = imath.FloatArray(len(widths))
    for k, w in enumerate(widths):
        width_values[k] = w
    # kUniformScope: one width per curve.
    width_sample = AbcGeom.OFloatGeomParamSample(width_values, AbcGeom.GeometryScope.kUniformScope)
    sample = AbcGeom.OCurvesSchemaSample(
        positions, counts, AbcGeom.CurveType.kLinear, AbcGeom.CurvePeriodicity.kNonPeriodic, width_sample
    )
    curves.getSchema().set(sample)
    return curves


def write_groom(path):
    archive = Abc.OArchive(path)  # Ogawa is PyAlembic's default back end.
    top = archive.getTop()
    head = AbcGeom.OXform(top, "head")
    sample = AbcGeom.XformSample()
    sample.setTranslation(imath.V3d(3.0, -2.0, 5.0))
    sample.setRotation(imath.V3d(1.0, 2.0, 0.5).normalized(), 40.0)
    sample.setScale(imath.V3d(2.0, 2.0, 2.0))
    head.getSchema().set(sample)
    scalp = AbcGeom.OXform(head, "scalp")
    m = imath.M44d()
    m.rotate(imath.V3d(0.3, -0.2, 0.9))
    m.shear(imath.V3d(0.1, 0.0, 0.0))
    m.translate(imath.V3d(0.5, 1.0, -1.5))
    scalp_sample = AbcGeom.XformSample()
    scalp_sample.setMatrix(m)
    scalp.getSchema().set(scalp_sample)
    widths_a = [0.05 + 0.01 * s for s in range(len(strands_a()))]
    write_curves(scalp, "hair", strands_a(), widths_a)
    loose = AbcGeom.OXform(head, "loose")
    loose_sample = AbcGeom.XformSample()
    loose_sample.setTranslation(imath.V3d(0.0, 7.0, 0.0))
    loose_sample.setInheritsXforms(False)
    loose.getSchema().set(loose_sample)
    widths_b = [0.02, 0.03, 0.04]
    write_curves(loose, "flyaways", strands_b(), widths_b)
    return widths_a, widths_b


DAMAGE = ("--bad-counts", "--nan-point", "--no-curves")


def write_damaged(path, damage):
    """A groom the reader must refuse: PyAlembic writes what it is given, unchecked."""
    archive = Abc.OArchive(path)
    head = AbcGeom.OXform(archive.getTop(), "head")
    head.getSchema().set(AbcGeom.XformSample())
    if damage != "--no-curves":
        write_curves(head, "hair", strands_a(), [0.05] * len(strands_a()), damage)


def world_matrix(obj):
    """The object's local-to-world matrix, from Alembic's own XformSample.getMatrix()."""
    m = imath.M44d()
    node = obj.getParent()
    while node is not None and node.getName() != "ABC":
        if AbcGeom.IXform.matches(node.getHeader()):
            sample = AbcGeom.IXform(node, Abc.WrapExistingFlag.kWrapExisting).getSchema().getValue()
            m = m * sample.getMatrix()  # row vectors: the child's matrix applies first
            if not sample.getInheritsXforms():
                break
        node = node.getParent()
    return m


def expected(path):
    archive = Abc.IArchive(path)
    strands = []
    for name in ("head/scalp/hair", "head/loose/flyaways"):
        node = archive.getTop()
        for part in name.split("/"):
            node = node.getChild(part)
        curves = AbcGeom.ICurves(node, Abc.WrapExistingFlag.kWrapExisting)
        sample = curves.getSchema().getValue()
        widths = curves.getSchema().getWidthsParam().getExpandedValue().getVals()
        m = world_matrix(node)
        scale = abs(m.determinant()) ** (1.0 / 3.0)
        positions, counts = sample.getPositions(), sample.getCurvesNumVertices()
        start = 0
        for k in range(len(counts)):
            points = [positions[start + i] * m for i in range(counts[k])]
            strands.append({"points": [[p.x, p.y, p.z] for p in points], "width": widths[k] * scale})
            start += counts[k]
    return {"strands": strands}


def write_benchmark(out_dir, usdc):
    """The linear curves of a usd-core benchmark stage (write_usd_groom.py --strands), as Alembic."""
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(usdc)
    curves = UsdGeom.BasisCurves(stage.GetPrimAtPath("/Hair"))
    points = curves.GetPointsAttr().Get()
    counts = curves.GetCurveVertexCountsAttr().Get()
    archive = Abc.OArchive(os.path.join(out_dir, "bench.abc"))
    out = AbcGeom.OCurves(archive.getTop(), "hair")
    positions = imath.V3fArray(len(points))
    for i, p in enumerate(points):
        positions[i] = imath.V3f(p[0], p[1], p[2])
    n = imath.IntArray(len(counts))
    for k, c in enumerate(counts):
        n[k] = c
    out.getSchema().set(AbcGeom.OCurvesSchemaSample(positions, n, AbcGeom.CurveType.kLinear))


def main():
    out_dir = sys.argv[1]
    os.makedirs(out_dir, exist_ok=True)
    if "--from-usd" in sys.argv:
        write_benchmark(out_dir, sys.argv[sys.argv.index("--from-usd") + 1])
        return
    damage = next((a for a in sys.argv[2:] if a in DAMAGE), None)
    if damage:
        write_damaged(os.path.join(out_dir, "groom.abc"), damage)
        return
    path = os.path.join(out_dir, "groom.abc")
    write_groom(path)
    with open(os.path.join(out_dir, "expected.json"), "w") as f:
        json.dump(expected(path), f, indent=1)


if __name__ == "__main__":
    main()
