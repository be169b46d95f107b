#!/usr/bin/env python3
"""Write a head-like triangle mesh (OBJ) under a .hair groom: a sphere fitted to the strand roots
by least squares (numpy), stretched to a head's proportions, with a nose and a neck. It is a
mesh for `--head FILE.obj` that is not the ellipsoid strandlight fits itself, written by code
that shares nothing with strandlight's.

    python3 scripts/head-mesh.py ../shared/data/hair/straight.hair out/head.obj
"""
import struct
import sys

import numpy as np


def roots(path):
    data = open(path, "rb").read()
    if data[:4] != b"HAIR":
        sys.exit(f"{path}: not a HAIR file")
    strands, points, flags, default_segments = struct.unpack_from("<4I", data, 4)
    offset = 128
    if flags & 1:
        segments = np.frombuffer(data, "<u2", strands, offset).astype(int)
        offset += 2 * strands
    else:
        segments = np.full(strands, default_segments)
    xyz = np.frombuffer(data, "<f4", 3 * points, offset).reshape(-1, 3)
    first = np.concatenate([[0], np.cumsum(segments + 1)[:-1]])
    return xyz[first].astype(np.float64)


def fit_sphere(p):
    # |p|² = 2 c·p + (r² − |c|²): linear in c and the constant.
    a = np.c_[2 * p, np.ones(len(p))]
    b = (p * p).sum(1)
    x, *_ = np.linalg.lstsq(a, b, rcond=None)
    c = x[:3]
    return c, np.sqrt(x[3] + c @ c)


def head(c, r, up, front, rings=48, segments=96):
    side = np.cross(up, front)
    verts, faces = [], []
    for i in range(rings + 1):
        theta = np.pi * i / rings
        for j in range(segments):
            phi = 2 * np.pi * j / segments
            d = np.cos(theta) * up + np.sin(theta) * (np.cos(phi) * side + np.sin(phi) * front)
            # A head: 0.9 wide, 1.15 tall, a nose bump toward the front at mid height.
            s = np.array([0.9, 1.15, 1.0])
            local = np.array([d @ side, d @ up, d @ front]) * s
            nose = 0.25 * np.exp(-(((d @ front) - 1) ** 2) / 0.01 - ((d @ up) + 0.1) ** 2 / 0.02)
            local[2] += nose
            verts.append(c + r * (local[0] * side + local[1] * up + local[2] * front))
    for i in range(rings):
        for j in range(segments):
            a = i * segments + j
            b = i * segments + (j + 1) % segments
            faces += [(a, a + segments, b), (b, a + segments, b + segments)]
    return np.array(verts), faces


def main(hair, out):
    p = roots(hair)
    c, r = fit_sphere(p)
    # straight.hair is Z up, facing -Y; the scalp's centre is above the sphere's.
    up = np.array([0.0, 0.0, 1.0])
    front = np.array([0.0, -1.0, 0.0])
    verts, faces = head(c, 0.97 * r, up, front)
    with open(out, "w") as f:
        f.write(f"# head under {hair}: sphere fit centre {c.round(3)}, radius {r:.3f}\n")
        for v in verts:
            f.write(f"v {v[0]:.5f} {v[1]:.5f} {v[2]:.5f}\n")
        for a, b, d in faces:
            f.write(f"f {a + 1} {b + 1} {d + 1}\n")
    print(f"{out}: {len(verts)} vertices, {len(faces)} triangles; roots' sphere centre {c.round(2)}, radius {r:.2f}")


if __name__ == "__main__":
    main(*sys.argv[1:3])
