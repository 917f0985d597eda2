"""The teaching view as a web page: ``warpviz serve SCENE`` in a browser, or :class:`TeachingApp` in Jupyter.

:mod:`warpviz.web.controls` (sliders, clicks) is pure Python; :mod:`warpviz.web.app` needs the optional
``pip install "warpviz[web]"`` (trame) and is imported only when used.
"""

from __future__ import annotations

__all__ = ["TeachingApp", "serve"]


def __getattr__(name: str):
    if name in __all__:
        from warpviz.web import app

        return getattr(app, name)
    raise AttributeError(f"module 'warpviz.web' has no attribute {name!r}")
