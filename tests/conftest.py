import json
import math
from pathlib import Path

import numpy as np
import pytest

import warpviz as wv

DATA = Path(__file__).parent / "data"


@pytest.fixture(scope="session")
def exact():
    """Exact reference values (copy of the team's shared/reference/exact_values.json)."""
    return json.loads((DATA / "exact_values.json").read_text())


def launch_direction(r0: float, b: float, mass: float = 1.0) -> np.ndarray:
    """Direction, in the static frame at (-r0, 0, 0), of a Schwarzschild ray with impact parameter b
    moving towards +x and deflected in the x-y plane: sin(angle from radial) = b sqrt(1 - 2M/r0) / r0."""
    s = b * math.sqrt(1.0 - 2.0 * mass / r0) / r0
    return np.array([math.sqrt(1.0 - s * s), s, 0.0])


def deflection(metric, r0: float, direction, **kw) -> float:
    """Total deflection of the ray through (-r0, 0, 0) along `direction`, from its two asymptotic
    directions (traced forward and backward), as the clockwise turning angle in [0, 2 pi)."""
    rays = wv.trace(metric, [-r0, 0.0, 0.0], [direction, -np.asarray(direction)], **kw)
    assert rays.status_names.tolist() == ["escaped", "escaped"], rays
    n_out, n_in = rays.final_directions[0], -rays.final_directions[1]
    turn = math.atan2(np.cross(n_in, n_out)[2], float(n_in @ n_out))
    return (-turn) % (2 * math.pi)


#: Line elements the contract tests load as plugins beside the built-in metrics: a Kerr-Schild chart
#: (horizon-penetrating) and a static spherical one (absorbed at the capture radius), with a definition.
EXPRESSION_METRICS = {
    "ks_schwarzschild": dict(
        line_element="-dt**2 + dx**2 + dy**2 + dz**2 + 2*M/r*(dt + (x*dx + y*dy + z*dz)/r)**2",
        parameters={"M": 1.0}, horizon_radius="2*M", photon_sphere_radius="3*M", mass="M"),
    "static_charged": dict(
        line_element="-f*dt**2 + dr**2/f + r**2*dOmega**2", coordinates="spherical",
        definitions={"f": "1 - 2*M/r + Q**2/r**2"}, parameters={"M": 1.0, "Q": 0.8},
        horizon_radius="M + sqrt(M**2 - Q**2)", inner_horizon_radius="M - sqrt(M**2 - Q**2)",
        photon_sphere_radius="(3*M + sqrt(9*M**2 - 8*Q**2))/2", mass="M"),
    # the Ellis wormhole in its proper radial distance: two sheets, the chart's inversion between them
    "ellis_expr": dict(
        line_element="-dt**2 + dl**2 + (b**2 + l**2)*dOmega**2", coordinates="wormhole", parameters={"b": 1.5},
        throat_radius="b"),
}  # fmt: skip


def expression_metric(key: str):
    """A metric of :data:`EXPRESSION_METRICS`, compiled on first use (cached in warpviz's plugin cache)."""
    return wv.Metric.from_line_element(name=key, **EXPRESSION_METRICS[key])


def metric_instances():
    """One instance of every metric compiled into the core, with its registry example parameters (GYOTO
    style: a new metric file is covered by every contract test without a test edit), and the metrics of
    :data:`EXPRESSION_METRICS` loaded as plugins (skipped where no C++ compiler is found)."""
    from warpviz.spacetime.line_element.plugin import CompilerNotFoundError

    try:
        for key in EXPRESSION_METRICS:
            expression_metric(key)
    except CompilerNotFoundError:
        pass
    return [wv.metric_class(entry["name"]).example() for entry in wv.registered_metrics()]
