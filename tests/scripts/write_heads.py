"""Writes a small head (a box for the face, two tetrahedra for the eyes) as glTF 2.0 with
pygltflib (`head.glb`, `head.gltf` with its buffer in `head.bin`, and `head-embedded.gltf`
with it as a data URI) and as USD Mesh prims with
Pixar's usd-core (`head.usda`, `head.usdc`, `head.usdz`), and beside them `expected.json`: for
each format the triangle count, total area, area-weighted centroid, bounds and the centre of
each closed part and the volume they enclose, in strandlight's world (Y up, centimetres), computed here from the writer's
own transforms (usd-core's ComputeLocalToWorldTransform; for glTF, the node TRS composed with
numpy as the glTF 2.0 specification defines it).

Both files are awkward on purpose: glTF nodes nested with translation / rotation / scale and a
matrix, a mirrored node (negative determinant: its winding must flip to keep normals outward),
one primitive with 16-bit indices, one with 32-bit, one without indices; USD Z up in
millimetres, nested xform ops, quads and triangles, a leftHanded prim, and a proxy and an
invisible prim that a renderer does not draw.

Usage: python3 write_heads.py OUT_DIR
"""

import json
import math
import os
import sys

import numpy as np

BOX = (
    [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)],
    # Quads, counter-clockwise seen from outside (right-handed, outward normals).
    [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (1, 2, 6, 5), (0, 4, 7, 3)],
)
TETRA = (
    [(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)],
    [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)],
)


def fan(faces):
    return [(f[0], f[i], f[i + 1]) for f in faces for i in range(1, len(f) - 1)]


def summary(parts):
    """parts: list of (world points (n, 3) array, triangles) of closed meshes."""
    area, moment, count, volume = 0.0, np.zeros(3), 0, 0.0
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    centres = []
    for points, triangles in parts:
        lo, hi = np.minimum(lo, points.min(axis=0)), np.maximum(hi, points.max(axis=0))
        centres.append(points.mean(axis=0).tolist())
        # Each part is closed: its enclosed volume, whatever way a transform turned its faces.
        volume += abs(sum(np.dot(points[a], np.cross(points[b], points[c])) for a, b, c in triangles) / 6.0)
        for a, b, c in triangles:
            pa, pb, pc = points[a], points[b], points[c]
            s = 0.5 * np.linalg.norm(np.cross(pb - pa, pc - pa))
            area += s
            moment += s * (pa + pb + pc) / 3.0
            count += 1
    return {
        "triangles": count,
        "volume": volume,
        "area": area,
        "centroid": (moment / area).tolist(),
        "min": lo.tolist(),
        "max": hi.tolist(),
        "part_centres": centres,
    }


def trs(t=(0, 0, 0), r=(0, 0, 0, 1), s=(1, 1, 1)):
    """glTF's node matrix T * R * S (rotation a unit quaternion x, y, z, w)."""
    x, y, z, w = r
    rot = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    m = np.eye(4)
    m[:3, :3] = rot @ np.diag(s)
    m[:3, 3] = t
    return m


def apply(m, points):
    p = np.hstack([np.asarray(points, float), np.ones((len(points), 1))])
    return (m @ p.T).T[:, :3]


def write_gltf(out):
    from pygltflib import (
        ARRAY_BUFFER, BufferFormat, ELEMENT_ARRAY_BUFFER, FLOAT, GLTF2, UNSIGNED_INT, UNSIGNED_SHORT, Accessor,
        Asset, Attributes, Buffer, BufferView, Mesh, Node, Primitive, Scene,
    )

    blob = bytearray()
    views, accessors = [], []

    def add(array, component, target, kind):
        while len(blob) % 4:
            blob.append(0)
        data = array.tobytes()
        views.append(BufferView(buffer=0, byteOffset=len(blob), byteLength=len(data), target=target))
        blob.extend(data)
        acc = Accessor(bufferView=len(views) - 1, componentType=component, count=len(array), type=kind)
        if kind == "VEC3":
            acc.min, acc.max = array.min(axis=0).tolist(), array.max(axis=0).tolist()
        accessors.append(acc)
        return len(accessors) - 1

    box_points = np.array(BOX[0], np.float32) * np.array([0.8, 1.0, 0.9], np.float32)
    box_tris = fan(BOX[1])
    tetra = np.array(TETRA[0], np.float32) * 0.15
    face = Primitive(
        attributes=Attributes(POSITION=add(box_points, FLOAT, ARRAY_BUFFER, "VEC3")),
        indices=add(np.array(box_tris, np.uint16).ravel(), UNSIGNED_SHORT, ELEMENT_ARRAY_BUFFER, "SCALAR"),
    )
    left_eye = Primitive(
        attributes=Attributes(POSITION=add(tetra + np.float32([-0.35, 0.3, 0.9]), FLOAT, ARRAY_BUFFER, "VEC3")),
        indices=add(np.array(TETRA[1], np.uint32).ravel(), UNSIGNED_INT, ELEMENT_ARRAY_BUFFER, "SCALAR"),
    )
    # Without indices: every three vertices a triangle.
    unrolled = np.array([tetra[i] for t in TETRA[1] for i in t], np.float32) + np.float32([0.35, 0.3, 0.9])
    right_eye = Primitive(attributes=Attributes(POSITION=add(unrolled, FLOAT, ARRAY_BUFFER, "VEC3")))

    head_m = trs(t=(0.02, 1.55, -0.01), r=(0, math.sin(math.radians(15)), 0, math.cos(math.radians(15))), s=(0.11, 0.11, 0.11))
    face_m = trs(t=(0, 0.1, 0), s=(1.0, 1.2, 1.0))
    # The eyes' node: a matrix (column-major in the file), mirrored in x.
    eyes_m = trs(t=(0, 0.05, 0.05), s=(-1.0, 1.0, 1.0))
    g = GLTF2(
        asset=Asset(version="2.0"),
        scene=0,
        scenes=[Scene(nodes=[0])],
        nodes=[
            Node(name="Head", translation=list(head_m[:3, 3]), rotation=[0, math.sin(math.radians(15)), 0, math.cos(math.radians(15))], scale=[0.11] * 3, children=[1, 2]),
            Node(name="Face", mesh=0, translation=[0, 0.1, 0], scale=[1.0, 1.2, 1.0]),
            Node(name="Eyes", mesh=1, matrix=eyes_m.T.ravel().tolist()),
        ],
        meshes=[Mesh(name="face", primitives=[face]), Mesh(name="eyes", primitives=[left_eye, right_eye])],
        accessors=accessors,
        bufferViews=views,
        buffers=[Buffer(byteLength=len(blob))],
    )
    g.set_binary_blob(bytes(blob))
    g.save_binary(os.path.join(out, "head.glb"))
    g.buffers[0].uri = "head.bin"
    with open(os.path.join(out, "head.bin"), "wb") as f:
        f.write(bytes(blob))
    g.set_binary_blob(None)
    g.save_json(os.path.join(out, "head.gltf"))
    # The same file with its buffer inside, as a base64 data URI (a self-contained .gltf).
    g.buffers[0].uri = None
    g.set_binary_blob(bytes(blob))
    g.convert_buffers(BufferFormat.DATAURI)
    g.save_json(os.path.join(out, "head-embedded.gltf"))

    to_cm = np.diag([100.0, 100.0, 100.0, 1.0])
    face_world = apply(to_cm @ head_m @ face_m, box_points)
    eyes = to_cm @ head_m @ eyes_m
    left = apply(eyes, tetra + np.float32([-0.35, 0.3, 0.9]))
    right = apply(eyes, tetra + np.float32([0.35, 0.3, 0.9]))
    return summary([(face_world, box_tris), (left, TETRA[1]), (right, TETRA[1])])


def write_usd(out):
    from pxr import Gf, Sdf, Usd, UsdGeom, UsdUtils, Vt

    meters_per_unit = 0.001
    path = os.path.join(out, "head.usda")
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, meters_per_unit)
    head = UsdGeom.Xform.Define(stage, "/Head")
    head.AddTranslateOp().Set(Gf.Vec3d(20.0, -10.0, 1550.0))
    head.AddRotateXYZOp().Set(Gf.Vec3f(0.0, 0.0, 25.0))
    head.AddScaleOp().Set(Gf.Vec3f(110.0, 110.0, 110.0))
    face = UsdGeom.Mesh.Define(stage, "/Head/Face")
    face.AddTranslateOp().Set(Gf.Vec3d(0.0, 0.0, 0.1))
    box_points = [Gf.Vec3f(0.8 * x, 0.9 * y, 1.1 * z) for x, y, z in BOX[0]]
    face.CreatePointsAttr(Vt.Vec3fArray(box_points))
    face.CreateFaceVertexCountsAttr(Vt.IntArray([4] * len(BOX[1])))
    face.CreateFaceVertexIndicesAttr(Vt.IntArray([i for f in BOX[1] for i in f]))
    eye = UsdGeom.Mesh.Define(stage, "/Head/Eye")
    eye_points = [Gf.Vec3f(0.15 * x, 0.15 * y + 0.9, 0.15 * z + 0.3) for x, y, z in TETRA[0]]
    eye.CreatePointsAttr(Vt.Vec3fArray(eye_points))
    eye.CreateFaceVertexCountsAttr(Vt.IntArray([3] * 4))
    # Clockwise faces, declared leftHanded: the same outward surface.
    eye.CreateFaceVertexIndicesAttr(Vt.IntArray([i for t in TETRA[1] for i in (t[0], t[2], t[1])]))
    eye.CreateOrientationAttr(UsdGeom.Tokens.leftHanded)
    proxy = UsdGeom.Mesh.Define(stage, "/Head/Proxy")
    proxy.CreatePurposeAttr(UsdGeom.Tokens.proxy)
    hidden = UsdGeom.Mesh.Define(stage, "/Head/Hidden")
    hidden.CreateVisibilityAttr(UsdGeom.Tokens.invisible)
    for prim in (proxy, hidden):
        prim.CreatePointsAttr(Vt.Vec3fArray([Gf.Vec3f(50, 50, 50), Gf.Vec3f(51, 50, 50), Gf.Vec3f(50, 51, 50)]))
        prim.CreateFaceVertexCountsAttr(Vt.IntArray([3]))
        prim.CreateFaceVertexIndicesAttr(Vt.IntArray([0, 1, 2]))
    stage.GetRootLayer().Save()
    stage.Export(os.path.join(out, "head.usdc"))
    UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(os.path.join(out, "head.usdc")), os.path.join(out, "head.usdz"))

    def world(mesh, points):
        m = np.array(mesh.ComputeLocalToWorldTransform(Usd.TimeCode.Default()))  # row vectors
        p = apply(m.T, [tuple(v) for v in points])
        # Z up to Y up ((x, y, z) -> (x, z, -y)), then to centimetres.
        return np.stack([p[:, 0], p[:, 2], -p[:, 1]], axis=1) * meters_per_unit * 100.0

    return summary([(world(face, box_points), fan(BOX[1])), (world(eye, eye_points), TETRA[1])])


def main():
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    expected = {"gltf": write_gltf(out), "usd": write_usd(out)}
    with open(os.path.join(out, "expected.json"), "w") as f:
        json.dump(expected, f, indent=1)


if __name__ == "__main__":
    main()
