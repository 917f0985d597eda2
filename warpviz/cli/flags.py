"""The flags several commands share (``render`` and ``trace``), each defined once: its name, range and help.

A command's own flags stay in its module; a flag two commands take is a constant here, used as the default
of both parameters, so the two cannot drift apart.
"""

from __future__ import annotations

import typer

from warpviz.cli.common import _parse_size
from warpviz.limits import EXPOSURE_RANGE, MAX_IMAGE_SIDE, MAX_SEED
from warpviz.options import option_help

SIZE = typer.Option(None, "--size", callback=_parse_size,
                    help=f"Image size WIDTHxHEIGHT, e.g. 320x240 (each at most {MAX_IMAGE_SIDE}).")  # fmt: skip
THREADS = typer.Option(0, "--threads", min=0, help="Worker threads; 0 uses every core.")
SEED = typer.Option(None, "--seed", min=0, max=MAX_SEED, help=option_help("seed"))
FLAT = typer.Option(False, "--flat", help="Render the same scene in flat space, for comparison.")
PAPER = typer.Option(False, "--paper", help="Use the scene's [render.paper] size and sample count.")
EXPOSURE = typer.Option(
    None, "--exposure",
    help=f"PNG only: exposure in stops, the radiance times 2**S before tonemapping, in "
    f"[{EXPOSURE_RANGE[0]:g}, {EXPOSURE_RANGE[1]:g}] (default: the scene's [outputs] exposure, else 0).",
)  # fmt: skip
TONEMAP = typer.Option(
    None, "--tonemap",
    help="PNG only: 'filmic' (default: hue-preserving shoulder, saturated lights keep their colour), 'clip' "
    "(each channel clamped to 1) or 'reinhard' (x / (1 + x) per channel). Default: the scene's [outputs] "
    "tonemap, else filmic.",
)  # fmt: skip
FORCE = typer.Option(False, "--force", help="Replace existing output files that warpviz did not write.")
QUIET = typer.Option(False, "--quiet", "-q", help="No progress bar.")
WORKERS = typer.Option(
    None, "--workers", min=1,
    help="Render on a local Dask cluster of this many worker processes, one thread each (pip install "
    "'warpviz[dask]'); the image is bit-identical to the local render. The dashboard's address is printed.",
)  # fmt: skip
CLUSTER = typer.Option(
    None, "--cluster",
    help="Render on the running Dask scheduler at this address, e.g. tcp://10.0.0.5:8786 (docs/cluster.md: "
    "SLURM, SSH); every worker needs this warpviz. The image is bit-identical to the local render.",
)  # fmt: skip
TILE = typer.Option(
    None, "--tile", min=1, max=MAX_IMAGE_SIDE,
    help="With --workers or --cluster: tile side in pixels, each tile's pass one task (default 128; with photons "
    "one tile per task slot, each tracing the whole image's photon passes).",
)  # fmt: skip
