"""Renders one strandlight scene in Mitsuba 3: the path-traced ground truth.

Called by strandlight (eval/src/ground_truth.rs) as `python3 mitsuba_render.py SCENE.json`.
SCENE.json names every input; nothing here chooses a setting. The film is linear RGBA: RGB is
the hair's radiance times its pixel coverage over black (emitters seen directly are hidden), A is
the coverage, the same convention as strandlight's frames. Prints one JSON line with the time.
"""
import json
import sys
import time

try:
    import mitsuba as mi
except ImportError:
    sys.stderr.write("error: Mitsuba 3 is not installed for this Python (pip install mitsuba)\n")
    sys.exit(3)


def main(path):
    with open(path) as f:
        scene = json.load(f)
    mi.set_variant(scene.get("variant", "scalar_rgb"))
    from mitsuba import ScalarTransform4f as T

    cam = scene["camera"]
    width, height = cam["width"], cam["height"]
    fiber = scene["fiber"]
    bsdf = {
        "type": "hair",
        "eumelanin": fiber["eumelanin"],
        "pheomelanin": fiber["pheomelanin"],
        "longitudinal_roughness": fiber["longitudinal_roughness"],
        "azimuthal_roughness": fiber["azimuthal_roughness"],
        "int_ior": fiber["ior"],
        "ext_ior": 1.0,
        "scale_tilt": fiber["scale_tilt_degrees"],
    }
    if fiber.get("sigma_a") is not None:
        del bsdf["eumelanin"], bsdf["pheomelanin"]
        bsdf["sigma_a"] = {"type": "rgb", "value": fiber["sigma_a"]}
    description = {
        "type": "scene",
        "integrator": {
            "type": "path",
            "max_depth": scene["max_depth"],
            "hide_emitters": True,
        },
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": cam["fov_y_degrees"],
            "near_clip": cam["near"],
            "far_clip": cam["far"],
            "to_world": T().look_at(origin=cam["eye"], target=cam["target"], up=cam["up"]),
            "sampler": {
                "type": "independent",
                "sample_count": scene["spp"],
                "seed": scene.get("seed", 0),
            },
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "pixel_format": "rgba",
                "component_format": "float32",
                "rfilter": {"type": "box"},
            },
        },
    }
    environment = scene.get("environment")
    if environment:
        matrix = [list(row) + [0.0] for row in environment["to_world"]] + [[0.0, 0.0, 0.0, 1.0]]
        description["environment"] = {
            "type": "envmap",
            "filename": environment["map"],
            "to_world": mi.ScalarTransform4f(matrix),
        }
    for i, light in enumerate(scene.get("directional", [])):
        # Mitsuba's `direction` is where the light travels: away from the light.
        description[f"sun{i}"] = {
            "type": "directional",
            "direction": [-c for c in light["toward_light"]],
            "irradiance": {"type": "rgb", "value": light["irradiance"]},
        }
    for i, curves in enumerate(scene["curves"]):
        # B-splines: `hair` reads the fiber frame that `bsplinecurve` builds from the tangent.
        description[f"hair{i}"] = {"type": "bsplinecurve", "filename": curves, "bsdf": bsdf}
    head = scene.get("head")
    if head:
        # The head: an opaque Lambertian mesh (strandlight's skin), two-sided as strandlight
        # draws it.
        description["head"] = {
            "type": "obj",
            "filename": head["obj"],
            "bsdf": {
                "type": "twosided",
                "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": head["albedo"]}},
            },
        }
    start = time.time()
    loaded = mi.load_dict(description)
    image = mi.render(loaded)
    seconds = time.time() - start
    mi.Bitmap(image, mi.Bitmap.PixelFormat.RGBA).write(scene["output"])
    print(json.dumps({"seconds": seconds, "mitsuba": mi.__version__}))


if __name__ == "__main__":
    main(sys.argv[1])
