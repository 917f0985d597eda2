"""Small native scene dicts (docs/native-scene.md) built in code for the renderer tests."""

from __future__ import annotations


def metric(name: str = "minkowski", *params: float) -> dict:
    return {"name": name, "params": list(params)}


def furnace(*, albedo: float = 1.0, material: str = "diffuse", sky: float = 0.5, size=(16, 12), metric_spec=None,
            camera_distance: float = 6.0) -> dict:
    """A unit sphere of one material under a uniform sky."""
    mats = {
        "diffuse": {"type": "diffuse", "texture": 0},
        "mirror": {"type": "mirror", "reflectance": [albedo] * 3},
        "glass": {"type": "glass", "ior": 1.5, "tint": [albedo] * 3},
    }
    return {
        "metric": metric_spec or metric(),
        "camera": {"position": [0, -camera_distance, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 30,
                   "width": size[0], "height": size[1]},
        "textures": [{"type": "constant", "color": [albedo] * 3}],
        "materials": [mats[material]],
        "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1.0, "material": 0}],
        "environment": {"color": [sky] * 3},
    }


def sky_only(metric_spec: dict, *, camera, look_at=(0, 0, 0), fov: float, size, sky: float = 1.0) -> dict:
    """Nothing but a uniform sky and the metric's horizon."""
    return {
        "metric": metric_spec,
        "camera": {"position": list(camera), "look_at": list(look_at), "up": [0, 0, 1], "fov": fov,
                   "width": size[0], "height": size[1]},
        "materials": [],
        "shapes": [],
        "environment": {"color": [sky] * 3},
    }


def room(metric_spec: dict, *, size=(24, 18), half: float = 12.0, light: float = 3.0, spheres: bool = True) -> dict:
    """A closed Cornell-style room (red left wall, green right wall, white elsewhere, area light in the
    ceiling) of half-width `half` around the origin, where a mass may sit."""
    s = half
    white, red, green = 0, 1, 2
    shapes = [
        {"type": "quad", "corner": [-s, -s, -s], "edge_u": [2 * s, 0, 0], "edge_v": [0, 2 * s, 0], "material": white},
        {"type": "quad", "corner": [-s, -s, s], "edge_u": [0, 2 * s, 0], "edge_v": [2 * s, 0, 0], "material": white},
        {"type": "quad", "corner": [-s, s, -s], "edge_u": [2 * s, 0, 0], "edge_v": [0, 0, 2 * s], "material": white},
        {"type": "quad", "corner": [-s, -s, -s], "edge_u": [0, 0, 2 * s], "edge_v": [2 * s, 0, 0], "material": white},
        {"type": "quad", "corner": [-s, -s, -s], "edge_u": [0, 2 * s, 0], "edge_v": [0, 0, 2 * s], "material": red},
        {"type": "quad", "corner": [s, -s, -s], "edge_u": [0, 0, 2 * s], "edge_v": [0, 2 * s, 0], "material": green},
        {"type": "quad", "corner": [-light, -light, s - 0.01], "edge_u": [0, 2 * light, 0],
         "edge_v": [2 * light, 0, 0], "material": 3},
    ]
    if spheres:
        shapes.append({"type": "sphere", "center": [-0.5 * s, 0.4 * s, -0.7 * s], "radius": 0.3 * s, "material": 4})
        shapes.append({"type": "sphere", "center": [0.5 * s, -0.2 * s, -0.7 * s], "radius": 0.3 * s, "material": 0})
    return {
        "metric": metric_spec,
        "camera": {"position": [0, -0.9 * s, 0.2 * s], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov": 80,
                   "width": size[0], "height": size[1]},
        "textures": [{"type": "constant", "color": c} for c in ([0.73] * 3, [0.65, 0.05, 0.05], [0.12, 0.45, 0.15],
                                                               [1.0, 0.9, 0.8])],
        "materials": [
            {"type": "diffuse", "texture": 0},
            {"type": "diffuse", "texture": 1},
            {"type": "diffuse", "texture": 2},
            {"type": "emissive", "texture": 3, "strength": 12.0},
            {"type": "mirror", "reflectance": [0.9, 0.9, 0.9]},
        ],
        "shapes": shapes,
        "environment": {"color": [0, 0, 0]},
    }


def lamp_over_hole(metric_spec: dict, *, size=(24, 18), lamp: float = 5.0, half: float = 3.0,
                   ceiling: float = 6.0, normal_up: bool = False) -> dict:
    """A square lamp (half-width ``half``, at height ``lamp``) over a hole at the origin that shines only
    downwards (one-sided), a diffuse ceiling just above it (its normal down into the room, or up with
    ``normal_up``), seen from below and to the side. The ceiling sees only the lamp's dark back directly: all its
    direct light is the lamp's light the hole turned back up round the photon orbits (the images of order 1 and
    2, swept azimuth ~ 2 pi)."""
    edges = ([40, 0, 0], [0, 40, 0]) if normal_up else ([0, 40, 0], [40, 0, 0])
    return {
        "metric": metric_spec,
        "camera": {"position": [0, -26, 0], "look_at": [0, 0, ceiling], "up": [0, 0, 1], "fov": 50,
                   "width": size[0], "height": size[1]},
        "textures": [{"type": "constant", "color": [0.8, 0.8, 0.8]}, {"type": "constant", "color": [1, 1, 1]}],
        "materials": [{"type": "diffuse", "texture": 0}, {"type": "emissive", "texture": 1, "strength": 20.0}],
        "shapes": [
            {"type": "quad", "corner": [-20, -20, ceiling], "edge_u": edges[0], "edge_v": edges[1], "material": 0},
            {"type": "quad", "corner": [-half, -half, lamp], "edge_u": [0, 2 * half, 0], "edge_v": [2 * half, 0, 0],
             "material": 1},
        ],
        "environment": {"color": [0, 0, 0]},
    }
