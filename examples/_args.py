"""Command-line helpers shared by the example scripts (run as ``python examples/<name>.py``)."""

import argparse


def parse_size(text: str) -> tuple[int, int]:
    """``"WxH"`` to (W, H), for ``--size``; at least 2x2 pixels."""
    try:
        width, height = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, e.g. 128x64, got {text!r}") from None
    if width < 2 or height < 2:
        raise argparse.ArgumentTypeError(f"the image must be at least 2x2 pixels, got {text!r}")
    return width, height
