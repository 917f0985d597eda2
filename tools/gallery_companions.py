"""The companions the paper shows beside three of its figures, composed onto the gallery's pictures.

* fig05: the undistorted star field (the same sky without the hole) on the left, the marked star ringed;
  the lensed field on the right, its primary image circled and its secondary one marked by a triangle
  (the paper's figure 5). The images are found in the render itself: the connected patches of the marked
  star's colour, the one farther from the shadow's centre the primary.
* fig06a, fig06b: the paint swatch as it is, undistorted (the disk seen from straight above without
  gravity), inset in the lower left corner (the paper's figure 6).
* fig08: the right side of the glass ball enlarged (2.5 times, less where the ball fills the frame), inset
  in the upper left corner with a frame round the part it shows: two images of the room, refracted and bent along different paths (the
  paper's figure 8).

Each companion is a PNG beside the picture (``fig05_marked.png``, ``fig06a_swatch.png``, ``fig08_zoom.png``)
made from the picture (and, for fig05 and fig06, one small extra render of a second or two); the gallery
table shows it and links the plain picture.
"""

from __future__ import annotations

import math
from collections import deque
from pathlib import Path

import numpy as np

#: The scenes with a companion, and the suffix of its file.
COMPANIONS = {"fig05": "marked", "fig06a": "swatch", "fig06b": "swatch", "fig08": "zoom"}


def companion_path(pictures: Path, short: str) -> Path | None:
    """Where the companion of ``short`` goes (None: it has none)."""
    suffix = COMPANIONS.get(short)
    return None if suffix is None else pictures / f"{short}_{suffix}.png"


def project(camera: dict, point) -> tuple[float, float]:
    """Image coordinates (x right, y down, pixel units) of a user-frame point, in flat space."""
    from warpviz.scene.camera import camera_basis

    forward, right, up = camera_basis(camera)
    d = np.asarray(point, dtype=np.float64) - np.asarray(camera["position"], dtype=np.float64)
    f = 0.5 * camera["height"] / math.tan(math.radians(camera["fov"]) / 2)
    depth = float(d @ forward)
    return 0.5 * camera["width"] + f * float(d @ right) / depth, 0.5 * camera["height"] - f * float(d @ up) / depth


def patches(mask: np.ndarray) -> list[np.ndarray]:
    """The 8-connected patches of a boolean (H, W) mask, each as (K, 2) pixel coordinates (x, y), largest
    first."""
    seen = np.zeros_like(mask, dtype=bool)
    out = []
    h, w = mask.shape
    for y0, x0 in zip(*np.nonzero(mask)):
        if seen[y0, x0]:
            continue
        seen[y0, x0] = True
        queue, pix = deque([(y0, x0)]), []
        while queue:
            y, x = queue.popleft()
            pix.append((x, y))
            for dy in (-1, 0, 1):
                for dx in (-1, 0, 1):
                    ny, nx = y + dy, x + dx
                    if 0 <= ny < h and 0 <= nx < w and mask[ny, nx] and not seen[ny, nx]:
                        seen[ny, nx] = True
                        queue.append((ny, nx))
        out.append(np.array(pix))
    return sorted(out, key=len, reverse=True)


def _font(size: int):
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1
        return ImageFont.load_default()


def _label(draw, xy, text: str, size: int) -> None:
    x, y = xy
    font = _font(size)
    box = draw.textbbox((x, y), text, font=font)
    draw.rectangle((box[0] - 4, box[1] - 3, box[2] + 4, box[3] + 3), fill=(0, 0, 0))
    draw.text((x, y), text, fill=(255, 255, 255), font=font)


def _marked_star(rgb: np.ndarray, colour) -> np.ndarray:
    """Pixels where the marked star's hue dominates: red well above green and blue, and bright."""
    c = np.asarray(colour, dtype=np.float64)
    c = c / c.max()
    r, g, b = (rgb[..., k] for k in range(3))
    main = int(np.argmax(c))
    others = [k for k in range(3) if k != main]
    level = rgb[..., main]
    return (level > 0.05 * level.max()) & (level > 3 * rgb[..., others[0]]) & (level > 3 * rgb[..., others[1]])


def fig05(scene, picture: Path, exr: Path, out: Path, *, render=None) -> Path:
    """The star field without and with the hole, the marked star's images marked (see the module)."""
    import warpviz as wv
    from PIL import Image, ImageDraw

    render = render or wv.render
    lensed = wv.Image.open(exr)
    h, w = lensed.shape
    spot = scene.native()["environment"]["spots"][0]
    flat = render(scene, flat=True, width=w, height=h, spp=16, aovs=[], progress=None)
    flat_pic = Image.fromarray(flat.to_uint8()).convert("RGB")
    lensed_pic = Image.open(picture).convert("RGB")
    size = max(12, h // 24)
    cx, cy = project(scene.native(width=w, height=h)["camera"], [0.0, 0.0, 0.0])
    found = [p for p in patches(_marked_star(np.asarray(lensed.rgb), spot["color"])) if len(p) >= 1][:2]
    draw = ImageDraw.Draw(lensed_pic)
    if found:
        centres = [p.mean(axis=0) for p in found]
        order = np.argsort([-math.hypot(x - cx, y - cy) for x, y in centres])  # primary: farther out
        for rank, i in enumerate(order):
            x, y = centres[i]
            r = max(8.0, 1.5 * math.sqrt(len(found[i]))) + 6
            if rank == 0:
                draw.ellipse((x - r, y - r, x + r, y + r), outline=(255, 220, 0), width=3)
            else:
                draw.polygon([(x, y - 1.3 * r), (x - 1.15 * r, y + 0.75 * r), (x + 1.15 * r, y + 0.75 * r)],
                             outline=(255, 220, 0), width=3)  # fmt: skip
    fdraw = ImageDraw.Draw(flat_pic)
    stars = patches(_marked_star(np.asarray(flat.rgb), spot["color"]))
    if stars:
        x, y = stars[0].mean(axis=0)
        r = max(8.0, 1.5 * math.sqrt(len(stars[0]))) + 6
        fdraw.ellipse((x - r, y - r, x + r, y + r), outline=(255, 220, 0), width=3)
    _label(fdraw, (10, 8), "without the black hole: one image of the marked star", size)
    _label(draw, (10, 8), "with it: primary image (circle), secondary (triangle)", size)
    both = Image.new("RGB", (2 * w + 8, h), (255, 255, 255))
    both.paste(flat_pic, (0, 0))
    both.paste(lensed_pic, (w + 8, 0))
    both.save(out)
    return out


def fig06(scene, picture: Path, out: Path, *, render=None) -> Path:
    """The picture with the undistorted swatch (the disk from straight above, no gravity) inset."""
    import warpviz as wv
    from PIL import Image, ImageDraw

    render = render or wv.render
    pic = Image.open(picture).convert("RGB")
    w, h = pic.size
    side = h // 3
    native = scene.native(flat=True, width=side, height=side)
    disk = next(s for s in native["shapes"] if s["type"] == "disk")
    centre = np.asarray(disk["center"], dtype=np.float64)
    normal = np.asarray(disk["normal"], dtype=np.float64)
    normal = normal / np.linalg.norm(normal)
    reach = float(disk["outer_radius"])
    distance = 4.0 * reach
    up = np.cross(normal, [1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.cross(normal, [0.0, 1.0, 0.0])
    native["camera"].update(position=(centre + distance * normal).tolist(), look_at=centre.tolist(),
                            up=up.tolist(), fov=math.degrees(2 * math.atan(1.08 * reach / distance)))  # fmt: skip
    top = render(native, spp=16, aovs=[], progress=None)
    inset = Image.fromarray(top.to_uint8()).convert("RGB")
    pic.paste(inset, (6, h - side - 6))
    draw = ImageDraw.Draw(pic)
    draw.rectangle((5, h - side - 7, 6 + side, h - 6), outline=(255, 255, 255), width=2)
    _label(draw, (12, h - side), "the swatch, undistorted", max(10, h // 32))
    pic.save(out)
    return out


def fig08(scene, picture: Path, out: Path) -> Path:
    """The picture with the glass ball's right side enlarged (at most 2.5 times) in the upper left corner."""
    from PIL import Image, ImageDraw

    pic = Image.open(picture).convert("RGB")
    w, h = pic.size
    native = scene.native(width=w, height=h)
    ball = next(s for s in native["shapes"] if s["type"] == "sphere" and s["center"] == [0.0, 0.0, 0.0])
    cx, cy = project(native["camera"], ball["center"])
    ex, _ = project(native["camera"], np.asarray(ball["center"]) + [ball["radius"], 0.0, 0.0])
    r = abs(ex - cx)
    # between the shadow and the ball's right rim, where the paper's inset shows two images of the room
    box = (int(cx + 0.35 * r), int(cy - 0.35 * r), int(min(w - 1, cx + 1.02 * r)), int(cy + 0.45 * r))
    scale = min(2.5, 0.45 * w / (box[2] - box[0]), 0.55 * h / (box[3] - box[1]))
    zoom = pic.crop(box).resize((int(scale * (box[2] - box[0])), int(scale * (box[3] - box[1]))), Image.LANCZOS)
    zw, zh = zoom.size
    x0, y0 = 6, 6  # the upper left corner: the red wall, away from the ball's right side
    draw = ImageDraw.Draw(pic)
    draw.rectangle(box, outline=(255, 220, 0), width=2)
    pic.paste(zoom, (x0, y0))
    draw.rectangle((x0 - 1, y0 - 1, x0 + zw, y0 + zh), outline=(255, 220, 0), width=2)
    _label(draw, (x0 + 6, y0 + zh - max(12, h // 24) - 10), f"{scale:.1f}x: two images of the room", max(12, h // 24))
    pic.save(out)
    return out


def make_companion(short: str, scene, picture: Path, exr: Path) -> Path | None:
    """The companion of ``short`` beside ``picture`` (made from it and its EXR), or None if it has none."""
    out = companion_path(picture.parent, short)
    if out is None:
        return None
    if short == "fig05":
        return fig05(scene, picture, exr, out)
    if short.startswith("fig06"):
        return fig06(scene, picture, out)
    return fig08(scene, picture, out)
