"""Native scene dicts (``docs/native-scene.md``) for the render benchmarks, built in code so the
benchmarks run from a clean checkout without the tests or the scene-file loader.

The room follows ``scenes/fig07_schwarzschild_cornell.toml``: a closed Cornell box 100 M on a side
centred on the origin (red left wall, green right wall, white elsewhere, all normals inward), a 30 x 30
area light just below the ceiling facing down, and a camera at (0, -45, 0) looking at the centre with a
60 degree vertical field of view; the mass (if any) sits in the middle.
"""

from __future__ import annotations

import numpy as np

WHITE = [0.725, 0.71, 0.68]
RED = [0.63, 0.065, 0.05]
GREEN = [0.14, 0.45, 0.091]
LIGHT = [1.0, 0.9, 0.75]

#: Metric entries of the benchmark scenes: flat, fig07's hole (horizon radius 5), Kerr with the same
#: mass, an Ellis throat of the same radius as that horizon.
METRICS = {
    "flat": {"name": "minkowski", "params": []},
    "schwarzschild": {"name": "schwarzschild", "params": [2.5]},
    "kerr_a0.9": {"name": "kerr", "params": [2.5, 0.9]},
    "ellis": {"name": "ellis", "params": [5.0]},
}


def quad(corner, edge_u, edge_v, material: int) -> dict:
    """A quad entry; its front (normal ``edge_u x edge_v``) faces the inside of the room."""
    return {"type": "quad", "corner": list(corner), "edge_u": list(edge_u), "edge_v": list(edge_v),
            "material": material}


def cornell_room(metric: dict, *, size=(64, 48), half: float = 50.0, light_half: float = 15.0,
                 strength: float = 15.0, spheres: bool = False) -> dict:
    """The fig07-style room around ``metric``.

    Parameters
    ----------
    metric : dict
        Native metric entry, e.g. ``METRICS["schwarzschild"]``.
    size : (int, int), keyword-only
        Image width and height in pixels.
    half : float, keyword-only
        Half the side of the room (M).
    light_half : float, keyword-only
        Half the side of the ceiling light (M).
    strength : float, keyword-only
        Emitted radiance is ``strength * LIGHT``.
    spheres : bool, keyword-only
        Add two diffuse white spheres standing on the floor, left-back and right-front.

    Returns
    -------
    dict
        A native scene; the Ellis wormhole's other sheet gets a uniform grey sky.
    """
    s, L = float(half), float(light_half)
    white, red, green, light = 0, 1, 2, 3
    shapes = [
        quad([-s, -s, -s], [2 * s, 0, 0], [0, 2 * s, 0], white),  # floor
        quad([-s, -s, s], [0, 2 * s, 0], [2 * s, 0, 0], white),  # ceiling
        quad([-s, s, -s], [2 * s, 0, 0], [0, 0, 2 * s], white),  # back wall
        quad([-s, -s, -s], [0, 0, 2 * s], [2 * s, 0, 0], white),  # front wall, behind the camera
        quad([-s, -s, -s], [0, 2 * s, 0], [0, 0, 2 * s], red),  # left wall
        quad([s, -s, -s], [0, 0, 2 * s], [0, 2 * s, 0], green),  # right wall
        quad([-L, -L, s - 0.1], [0, 2 * L, 0], [2 * L, 0, 0], light),  # ceiling light, facing down
    ]
    if spheres:
        r = 0.2 * s
        shapes.append({"type": "sphere", "center": [-0.5 * s, 0.4 * s, -s + r], "radius": r, "material": white})
        shapes.append({"type": "sphere", "center": [0.5 * s, -0.3 * s, -s + r], "radius": r, "material": white})
    scene = {
        "metric": dict(metric),
        "camera": {"position": [0.0, -0.9 * s, 0.0], "look_at": [0.0, 0.0, 0.0], "up": [0.0, 0.0, 1.0], "fov": 60.0,
                   "width": int(size[0]), "height": int(size[1])},
        "textures": [{"type": "constant", "color": c} for c in (WHITE, RED, GREEN, LIGHT)],
        "materials": [
            {"type": "diffuse", "texture": white},
            {"type": "diffuse", "texture": red},
            {"type": "diffuse", "texture": green},
            {"type": "emissive", "texture": light, "strength": float(strength)},
        ],
        "shapes": shapes,
        "environment": {"color": [0.0, 0.0, 0.0]},
    }
    if metric["name"] == "ellis":
        scene["environment_other"] = {"color": [0.5, 0.5, 0.5]}
    return scene


def to_mitsuba(scene: dict, *, max_depth: int, rr_depth: int, spp: int) -> dict:
    """The same flat room as a Mitsuba 3 scene dict (``mitsuba.load_dict``).

    Quads become ``rectangle`` shapes whose to-world matrix maps [-1, 1]^2 onto the quad (columns
    edge_u / 2, edge_v / 2, the unit normal, the centre), diffuse materials ``diffuse`` BSDFs, the
    emissive quad a one-sided ``area`` emitter, spheres ``sphere`` shapes; the camera is a
    ``perspective`` sensor with the same vertical field of view, a box pixel filter and an
    ``independent`` sampler; the integrator is ``path`` (BSDF and emitter sampling with MIS).

    Parameters
    ----------
    scene : dict
        A flat native scene from :func:`cornell_room` (quads, spheres, diffuse and emissive materials,
        constant textures).
    max_depth, rr_depth, spp : int, keyword-only
        Path segments, first segment with Russian roulette, samples per pixel.

    Returns
    -------
    dict
        Plain Python values only; transforms are 4 x 4 nested lists (wrap them with
        ``mitsuba.ScalarTransform4f`` before loading, see :func:`mitsuba_transforms`).
    """
    if scene["metric"]["name"] != "minkowski":
        raise ValueError("only flat scenes can be handed to Mitsuba")
    cam = scene["camera"]
    out: dict = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": int(max_depth), "rr_depth": int(rr_depth)},
        "sensor": {
            "type": "perspective", "fov": float(cam["fov"]), "fov_axis": "y",
            "look_at": {"origin": cam["position"], "target": cam["look_at"], "up": cam["up"]},
            "film": {"type": "hdrfilm", "width": cam["width"], "height": cam["height"], "pixel_format": "rgb",
                     "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": int(spp)},
        },
    }  # fmt: skip
    for i, shape in enumerate(scene["shapes"]):
        mat = scene["materials"][shape["material"]]
        color = [float(c) for c in scene["textures"][mat["texture"]]["color"]]
        entry: dict
        if shape["type"] == "quad":
            c, u, v = (np.asarray(shape[k], dtype=float) for k in ("corner", "edge_u", "edge_v"))
            n = np.cross(u, v)
            n /= np.linalg.norm(n)
            m = np.eye(4)
            m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n, c + u / 2 + v / 2
            entry = {"type": "rectangle", "matrix": m.tolist()}
        elif shape["type"] == "sphere":
            entry = {"type": "sphere", "center": list(shape["center"]), "radius": float(shape["radius"])}
        else:
            raise ValueError(f"shape type {shape['type']!r} is not converted")
        if mat["type"] == "emissive":
            entry["emitter"] = {"type": "area", "radiance": {"type": "rgb",
                                                             "value": [mat["strength"] * x for x in color]}}
        elif mat["type"] == "diffuse":
            entry["bsdf"] = {"type": "diffuse", "reflectance": {"type": "rgb", "value": color}}
        else:
            raise ValueError(f"material type {mat['type']!r} is not converted")
        out[f"shape_{i}"] = entry
    return out


def mitsuba_transforms(spec: dict, mi) -> dict:
    """Turn :func:`to_mitsuba`'s plain transforms into Mitsuba objects (``to_world`` entries).

    Parameters
    ----------
    spec : dict
        Output of :func:`to_mitsuba`.
    mi : module
        ``mitsuba``, with a variant set.

    Returns
    -------
    dict
        A dict ``mitsuba.load_dict`` accepts.
    """
    out = {k: (dict(v) if isinstance(v, dict) else v) for k, v in spec.items()}
    look = out["sensor"].pop("look_at")
    out["sensor"]["to_world"] = mi.ScalarTransform4f().look_at(**look)
    for key, entry in out.items():
        if isinstance(entry, dict) and "matrix" in entry:
            entry["to_world"] = mi.ScalarTransform4f(entry.pop("matrix"))
    return out
