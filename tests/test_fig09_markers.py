"""fig09's marker stars: each shows twice in frame, its primary image outside the Einstein ring on its own
side and its smaller secondary image inside the ring on the opposite side (the scene's comment quotes the
measured angles)."""

import numpy as np
import pytest
from scipy import ndimage

import warpviz as wv

#: The markers' colours and the side of the view's centre their own direction lies on (x right, y up).
MARKERS = {"red": ([6.0, 0.6, 0.3], (1, 0)), "blue": ([0.4, 0.8, 6.0], (-1, 0)),
           "green": ([0.6, 6.0, 0.6], (0, 1)), "yellow": ([6.0, 5.0, 0.5], (0, -1))}


@pytest.fixture(scope="module")
def picture():
    return wv.render("fig09", width=200, height=150, spp=2, edge_samples=1).rgb.astype(np.float64)


@pytest.mark.parametrize("name", MARKERS)
def test_each_marker_has_a_primary_and_a_secondary_image_in_frame(picture, name):
    colour, side = MARKERS[name]
    c = np.asarray(colour) / np.linalg.norm(colour)
    norm = np.linalg.norm(picture, axis=2)
    mask = (picture @ c / np.maximum(norm, 1e-9) > 0.97) & (norm > 0.5)
    labels, n = ndimage.label(mask)
    sizes = ndimage.sum(mask, labels, range(1, n + 1))
    big = [i + 1 for i in np.argsort(sizes)[::-1][:2]]
    assert n >= 2 and sizes[big[1] - 1] >= 10
    h, w = mask.shape
    (y1, x1), (y2, x2) = (ndimage.center_of_mass(labels == i) for i in big)
    along = [((x - w / 2) * side[0] - (y - h / 2) * side[1]) for x, y in ((x1, y1), (x2, y2))]
    radius = [np.hypot(x - w / 2, y - h / 2) for x, y in ((x1, y1), (x2, y2))]
    assert along[0] > 0 > along[1]  # the larger image on the marker's own side, the other opposite
    assert radius[0] > radius[1]    # the primary outside the secondary
