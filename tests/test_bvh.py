"""The BVH hands the exact tests the primitives whose boxes a segment passes or a box overlaps, in order.

A small scene (at most 32 primitives) is one leaf whose boxes are tested four at a time in SIMD lanes
(``scene/bvh.cpp``); these tests hold that test to the scalar slab and overlap tests it replaced, written
here with the same IEEE operations (NaN from an origin on a slab plane along an axis-parallel ray included),
so every image stays bit-identical.
"""

import numpy as np
import pytest

from warpviz._native import testing

TMAX = 1e300


def slab_reference(boxes, seg):
    """Bvh::slab for each box: (lo - o) * inv per axis, swapped, tmin up / tmax down, the per-axis exit."""
    o, d, tmin0, tmax0 = seg[:3], seg[3:6], seg[6], seg[7]
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        out = np.zeros(len(boxes), bool)
        for i, b in enumerate(boxes):
            tmin, tmax, ok = tmin0, tmax0, True
            for a in range(3):
                t0, t1 = (b[a] - o[a]) * inv[a], (b[3 + a] - o[a]) * inv[a]
                if t0 > t1:
                    t0, t1 = t1, t0
                if t0 > tmin:
                    tmin = t0
                if t1 < tmax:
                    tmax = t1
                if tmin > tmax * (1.0 + 4e-16) + 1e-300:
                    ok = False
                    break
            out[i] = ok
    return out


def overlap_reference(boxes, q):
    apart = (boxes[:, :3] > q[3:]).any(axis=1) | (q[:3] > boxes[:, 3:]).any(axis=1)
    return ~apart


def random_case(rng, n):
    lo = rng.uniform(-10, 10, (n, 3))
    size = rng.uniform(0, 4, (n, 3))
    size[rng.random((n, 3)) < 0.2] = 0.0  # flat boxes, as a wall's quad has
    boxes = np.concatenate([lo, lo + size], axis=1)
    m = 400
    o = rng.uniform(-12, 12, (m, 3))
    d = rng.normal(size=(m, 3))
    d[rng.random((m, 3)) < 0.25] = 0.0  # axis-parallel rays: 1 / 0 = inf
    on = rng.random(m) < 0.3  # origins on a box's slab plane: (lo - o) * inf = NaN
    pick = rng.integers(0, n, m)
    axis = rng.integers(0, 3, m)
    o[on, axis[on]] = boxes[pick[on], axis[on]]
    d[np.all(d == 0, axis=1), 0] = 1.0
    tmin = np.where(rng.random(m) < 0.5, 0.0, rng.uniform(0, 2, m))
    tmax = np.where(rng.random(m) < 0.5, TMAX, tmin + rng.uniform(0, 20, m))
    segs = np.ascontiguousarray(np.concatenate([o, d, tmin[:, None], tmax[:, None]], axis=1))
    qlo = rng.uniform(-12, 12, (m, 3))
    queries = np.ascontiguousarray(np.concatenate([qlo, qlo + rng.uniform(0, 6, (m, 3))], axis=1))
    queries[: n, :] = boxes[: min(n, m)]  # boxes that touch exactly
    return np.ascontiguousarray(boxes), segs, queries


@pytest.mark.parametrize("n", [3, 4, 5, 18, 31, 32])
def test_a_small_scenes_leaf_passes_exactly_the_boxes_the_scalar_tests_pass_in_order(n):
    rng = np.random.default_rng(n)
    boxes, segs, queries = random_case(rng, n)
    got = testing.bvh_candidates(boxes, segs, queries)
    passed = 0
    for i, seg in enumerate(segs):
        ref = slab_reference(boxes, seg)
        order = got["segment_order"][i]
        np.testing.assert_array_equal(order > 0, ref, err_msg=f"segment {i}: {seg}")
        assert list(order[ref]) == list(range(1, ref.sum() + 1))  # visited in primitive order
        passed += ref.sum()
    assert 0 < passed < len(segs) * n  # the cases pass some boxes and miss others
    for i, q in enumerate(queries):
        ref = overlap_reference(boxes, q)
        order = got["box_order"][i]
        np.testing.assert_array_equal(order > 0, ref, err_msg=f"query {i}: {q}")
        assert list(order[ref]) == list(range(1, ref.sum() + 1))


@pytest.mark.parametrize("n", [33, 200])
def test_a_tree_hands_on_at_least_every_box_the_segment_passes(n):
    # (a larger scene is a tree of leaves of at most two primitives: no per-primitive box test there)
    rng = np.random.default_rng(n)
    boxes, segs, queries = random_case(rng, n)
    got = testing.bvh_candidates(boxes, segs, queries)
    for i, seg in enumerate(segs):
        assert np.all(got["segment_order"][i][slab_reference(boxes, seg)] > 0)
    for i, q in enumerate(queries):
        assert np.all(got["box_order"][i][overlap_reference(boxes, q)] > 0)
