"""What the teaching window's parts share: the help line's words and callbacks that do not keep the window
alive."""

from __future__ import annotations

import weakref

__all__ = ["IMAGE_TITLE", "KEYS_HELP", "weak_callback"]

#: The help line under the status line.
KEYS_HELP = "click a ray or a pixel    f: flat-space ray    c: colouring    n: more bounces"

#: The image panel's title.
IMAGE_TITLE = "What the camera sees"


def weak_callback(method, *, takes_args: bool = True):
    """A callable forwarding to a bound method without keeping its object alive (VTK observers hold
    their callbacks from C++, out of reach of Python's garbage collector). ``takes_args=False`` makes
    a callable of no arguments, as PyVista's key events want."""
    ref = weakref.WeakMethod(method)

    def call(*args):
        bound = ref()
        return None if bound is None else bound(*args)

    def call_without_args():
        bound = ref()
        return None if bound is None else bound()

    return call if takes_args else call_without_args
