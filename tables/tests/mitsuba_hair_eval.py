"""Evaluates Mitsuba 3's `hair` BSDF (Chiang et al. 2016) at given direction pairs, for the
cross-check in chiang_vs_mitsuba.rs.

Usage: python3 mitsuba_hair_eval.py CASES.json OUT.json

CASES.json: {"groups": [{"params": <ChiangParams as serialized by strandlight>,
                         "pairs": [[view_xyz, light_xyz], ...]}, ...]}
Directions are in Mitsuba's local frame of the hit (y = fiber tangent, z = surface normal);
`view` becomes `si.wi` (toward the viewer), `light` the `wo` argument of `eval` (toward the
light). OUT.json: {"mitsuba": version, "values": [[[r, g, b], ...], ...]} in the same order.
"""
import json
import sys

import mitsuba as mi

# scalar_rgb: the LLVM variants abort on some machines (see DESIGN.md).
mi.set_variant("scalar_rgb")


def hair(params):
    bsdf = {
        "type": "hair",
        "longitudinal_roughness": params["longitudinal_roughness"],
        "azimuthal_roughness": params["azimuthal_roughness"],
        "int_ior": params["ior"],
        "ext_ior": 1.0,
        "scale_tilt": params["scale_tilt_degrees"],
    }
    if params.get("sigma_a") is not None:
        # Mitsuba refuses melanin and sigma_a together.
        bsdf["sigma_a"] = {"type": "rgb", "value": params["sigma_a"]}
    else:
        bsdf["eumelanin"] = params["eumelanin"]
        bsdf["pheomelanin"] = params["pheomelanin"]
    return mi.load_dict(bsdf)


def main():
    with open(sys.argv[1]) as f:
        cases = json.load(f)
    ctx = mi.BSDFContext()
    si = mi.SurfaceInteraction3f()
    out = []
    for group in cases["groups"]:
        bsdf = hair(group["params"])
        values = []
        for view, light in group["pairs"]:
            si.wi = mi.Vector3f(*view)
            v = bsdf.eval(ctx, si, mi.Vector3f(*light))
            values.append([float(v[0]), float(v[1]), float(v[2])])
        out.append(values)
    with open(sys.argv[2], "w") as f:
        json.dump({"mitsuba": mi.__version__, "values": out}, f)


if __name__ == "__main__":
    main()
