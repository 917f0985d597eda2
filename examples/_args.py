"""Command-line helpers shared by the example scripts (run as ``python examples/<name>.py``)."""

import argparse
from pathlib import Path


def parse_size(text: str) -> tuple[int, int]:
    """``"WxH"`` to (W, H), for ``--size``; at least 2x2 pixels."""
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, e.g. 128x64, got {text!r}") from None
    if width < 2 or height < 2:
        raise argparse.ArgumentTypeError(f"the image must be at least 2x2 pixels, got {text!r}")
    return width, height


def positive_int(text: str) -> int:
    """An integer >= 1, for ``--spp``."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {value}")
    return value


def out_folder(text: str) -> Path:
    """A folder to write into, for ``--out``: it may not exist yet, but must not be a file."""
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a file; --out names a folder to write the results into")
    return path


def example_parser(doc: str, *, size: tuple[int, int]) -> argparse.ArgumentParser:
    """The options every example takes: ``--size WxH``, ``--spp`` and ``--out`` (default examples/output).

    Parameters
    ----------
    doc : str
        The script's docstring; its first paragraph becomes the description.
    size : (int, int), keyword-only
        Default image size.
    """
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--size", type=parse_size, default=size, help=f"image size WxH (default {size[0]}x{size[1]})")
    parser.add_argument("--spp", type=positive_int, default=4, help="samples per pixel (default 4)")
    parser.add_argument("--out", type=out_folder, default=Path(__file__).resolve().parent / "output",
                        help="output folder (default examples/output)")
    return parser
