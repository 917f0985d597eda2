"""A built wheel works on its own: it carries the shipped scenes with their meshes and textures, and renders
the README's main job without the checkout (tools/check_wheel.py; ``.ci/run`` runs it after the tests)."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
def test_the_wheel_carries_the_scenes_and_renders_fig02(tmp_path):
    result = subprocess.run([sys.executable, str(ROOT / "tools" / "check_wheel.py"), "--keep", str(tmp_path)],
                            capture_output=True, text=True, timeout=1800)  # fmt: skip
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    assert "the wheel works on its own" in result.stdout
