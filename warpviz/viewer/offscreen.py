"""Whether the teaching view opens a window or renders off-screen, decided from the environment alone.

Examples
--------
Whether a new window would be off-screen depends only on the environment:

>>> from warpviz.viewer import default_off_screen
>>> default_off_screen({"PYVISTA_OFF_SCREEN": "true", "DISPLAY": ":0"}, jupyter=False)
True
>>> default_off_screen({"DISPLAY": ":0"}, jupyter=False)
False
"""

from __future__ import annotations

import os
import sys
from collections.abc import Mapping

__all__ = ["default_off_screen"]


def _in_jupyter() -> bool:
    """True inside a Jupyter kernel (an IPython ZMQ shell)."""
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    try:
        shell = ipython.get_ipython()
    except AttributeError:  # pragma: no cover - very old IPython
        return False
    return shell is not None and type(shell).__name__ == "ZMQInteractiveShell"


def default_off_screen(environ: Mapping[str, str] | None = None, *, jupyter: bool | None = None) -> bool:
    """Whether :func:`view` renders off-screen when not told.

    Off-screen when ``PYVISTA_OFF_SCREEN`` is true, or on Linux-like systems when ``DISPLAY`` is unset
    outside Jupyter (no X server to open a window on); on-screen otherwise.

    Parameters
    ----------
    environ : mapping, optional
        Environment variables (default :data:`os.environ`).
    jupyter : bool, optional, keyword-only
        Whether we run in a Jupyter kernel (default: detected).

    Returns
    -------
    bool
    """
    env = os.environ if environ is None else environ
    if str(env.get("PYVISTA_OFF_SCREEN", "")).strip().lower() in ("1", "true", "yes", "on"):
        return True
    if _in_jupyter() if jupyter is None else jupyter:
        return False
    return sys.platform not in ("win32", "darwin") and not env.get("DISPLAY")
