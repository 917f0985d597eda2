"""A child process's ``warpviz`` command line that says "rendering" on stderr when its render's first
progress report comes, so a test can signal it once the render (not Python's start-up) is under way.

Run as ``python -c ANNOUNCING_CLI render ...`` (tests/test_hostile_input.py, tests/test_passes.py).
"""

ANNOUNCING_CLI = """
import contextlib, sys
from warpviz import cli
real = cli.common._progress_bar
@contextlib.contextmanager
def announcing(label, *, enabled, **kw):
    with real(label, enabled=False, **kw) as update:
        said = []
        def progress(done, total):
            if not said:
                print("rendering", file=sys.stderr, flush=True)
                said.append(True)
            update(done, total)
        progress.on_pass = update.on_pass
        yield progress
cli.common._progress_bar = announcing
sys.argv = ["warpviz"] + sys.argv[1:]
cli.main()
"""
