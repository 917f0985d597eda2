"""The web teaching view (``warpviz serve``): its pure parts, and the page in a real headless browser.

The browser test starts ``warpviz serve`` on a free port and drives the system's Chromium through
Playwright (``executable_path``: no browser is downloaded). It needs Debian's ``chromium`` package,
which ``.ci/run`` installs; on CI (``CI=true``) a missing browser is a failure, elsewhere a skip.
"""

from __future__ import annotations

import io
import os
import re
import shutil
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from warpviz.web.controls import apply_controls, image_click_to_pixel, slider_specs

KERR = {"metric": {"name": "kerr", "params": [1.0, 0.5]},
        "camera": {"position": [0.0, -30.0, 0.0], "look_at": [0.0, 0.0, 0.0]}}  # fmt: skip


def test_sliders_follow_the_registry_ranges():
    sliders = {s["name"]: s for s in slider_specs(KERR)}
    assert list(sliders) == ["mass", "spin", "distance"]
    spin = sliders["spin"]
    assert -1.0 < spin["min"] < -0.9 and 0.9 < spin["max"] < 1.0  # |spin| < 1, open at both ends
    assert sliders["mass"]["min"] == pytest.approx(0.25) and sliders["mass"]["max"] == pytest.approx(5.0)
    d = sliders["distance"]
    assert d["value"] == pytest.approx(30.0) and d["min"] == pytest.approx(15.0) and d["max"] == pytest.approx(60.0)
    for s in sliders.values():
        assert s["min"] <= s["value"] <= s["max"]
        assert s["step"] == pytest.approx((s["max"] - s["min"]) / 200)


def test_distance_slider_stays_out_of_the_capture_radius():
    close = {"metric": {"name": "schwarzschild", "params": [1.0]},
             "camera": {"position": [0.0, -6.0, 0.0], "look_at": [0.0, 0.0, 0.0]}}  # fmt: skip
    import warpviz as wv

    d = slider_specs(close)[-1]
    capture = wv.Schwarzschild(mass=1.0).landmarks["capture"]
    assert capture > 2.0 and d["min"] == pytest.approx(1.5 * capture)  # not half of 6 M


def test_apply_controls_moves_camera_along_its_line_of_sight_and_checks_the_metric():
    moved = apply_controls(KERR, {"spin": -0.3, "distance": 15.0, "mass": 2.0})
    assert moved["metric"]["params"] == [2.0, -0.3]
    np.testing.assert_allclose(moved["camera"]["position"], [0.0, -15.0, 0.0])
    assert KERR["camera"]["position"] == [0.0, -30.0, 0.0]  # the original is untouched
    with pytest.raises(ValueError, match="spin"):
        apply_controls(KERR, {"spin": 1.5})
    with pytest.raises(ValueError, match="unknown slider"):
        apply_controls(KERR, {"charge": 0.1})
    rn = {"metric": {"name": "reissner_nordstrom", "params": [1.0, 0.5]}, "camera": KERR["camera"]}
    with pytest.raises(ValueError, match="charge"):
        apply_controls(rn, {"charge": 1.2})  # |Q| < M: the metric's own relation


def test_image_click_to_pixel_scales_and_clamps():
    assert image_click_to_pixel(0.0, 0.0, shown=(480, 360), size=(96, 72)) == (0, 0)
    assert image_click_to_pixel(242.0, 183.0, shown=(480, 360), size=(96, 72)) == (48, 36)
    assert image_click_to_pixel(480.0, 360.0, shown=(480, 360), size=(96, 72)) == (95, 71)
    assert image_click_to_pixel(-3.0, 999.0, shown=(480, 360), size=(96, 72)) == (0, 71)


def test_picture_outlines_selected_and_recorded_pixels():
    pytest.importorskip("trame")
    from PIL import Image as PILImage

    from warpviz.web.app import picture_png

    img = np.zeros((6, 8, 3), dtype=np.uint8)
    big = np.asarray(PILImage.open(io.BytesIO(picture_png(img, [(2, 1)], scale=4, recorded=[(5, 4)]))))
    assert big.shape == (24, 32, 3)
    assert tuple(big[4, 8]) == (255, 0, 255) and tuple(big[5, 9]) == (0, 0, 0)  # outline, inside
    assert tuple(big[16, 20]) == (160, 160, 160)


def test_serve_without_trame_says_what_to_install(monkeypatch):
    from typer.testing import CliRunner

    import warpviz.web.app as web_app
    from warpviz.cli import app

    def missing():
        raise ImportError(web_app.MISSING_WEB)

    monkeypatch.setattr(web_app, "require_web", missing)
    result = CliRunner().invoke(app, ["serve", "fig04", "--no-browser"])
    assert result.exit_code == 2
    assert "warpviz[web]" in result.output


def test_serve_refuses_a_missing_scene():
    pytest.importorskip("trame")
    from typer.testing import CliRunner

    from warpviz.cli import app

    result = CliRunner().invoke(app, ["serve", "no/such/scene.toml", "--no-browser"])
    assert result.exit_code == 2 and "no/such/scene.toml: no such scene file" in result.output


# ---------------------------------------------------------------------------------------------- browser


def _chromium() -> str:
    for name in (os.environ.get("WARPVIZ_CHROMIUM"), "chromium", "chromium-browser", "google-chrome"):
        if name and shutil.which(name):
            return shutil.which(name)
    if os.environ.get("CI") == "true":
        pytest.fail("no Chromium on this CI machine: .ci/run installs Debian's chromium package")
    pytest.skip("no Chromium (apt-get install chromium) for the browser test")


@pytest.fixture
def served():
    """``warpviz serve fig09`` (Kerr a = 0.9 star field: quick to render) on a free port: its URL."""
    pytest.importorskip("trame")
    pytest.importorskip("playwright")
    env = dict(os.environ, PYVISTA_OFF_SCREEN="true")
    proc = subprocess.Popen([sys.executable, "-c", "from warpviz.cli import main; main()", "serve", "fig09",
                             "--port", "0", "--no-browser", "--spp", "2"],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)  # fmt: skip
    lines: list[str] = []
    found = threading.Event()

    def read():
        for line in proc.stdout:
            lines.append(line)
            if "serving the teaching view at" in line:
                found.set()

    threading.Thread(target=read, daemon=True).start()
    try:
        if not found.wait(120):
            pytest.fail("warpviz serve did not start:\n" + "".join(lines))
        url = re.search(r"(http://\S+)", "".join(lines)).group(1)
        yield url
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()


def _js_src_changed(page, old: str, timeout: float):
    page.wait_for_function("(s) => document.querySelector('#warpviz-image').src != s", arg=old, timeout=timeout)


def test_browser_shows_the_view_selects_pixels_and_rerenders_on_the_spin_slider(served):
    from PIL import Image as PILImage
    from playwright.sync_api import sync_playwright

    chromium = _chromium()
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=chromium, args=[
            "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox"])  # fmt: skip
        try:
            page = browser.new_page(viewport={"width": 1300, "height": 800})
            console = []
            page.on("console", lambda msg: console.append((msg.type, msg.text)))
            page.on("response", lambda r: console.append(("response", r.status, r.request.method, r.url)) if r.status >= 400 else None)
            page.goto(served)
            page.wait_for_function("document.querySelector('#warpviz-image')"
                                   " && document.querySelector('#warpviz-image').src.startsWith('data:image/png')",
                                   timeout=60_000)  # fmt: skip
            image = page.locator("#warpviz-image")
            picture = np.asarray(PILImage.open(io.BytesIO(image.screenshot())).convert("RGB"), dtype=np.float64)
            assert picture.std() > 5.0, "the picture is blank"

            # the 3-D panel: streamed from the server, not blank once its first frame arrived
            panel = page.locator("#warpviz-3d")
            deadline, spread = time.time() + 30, 0.0
            while time.time() < deadline and spread <= 5.0:
                shot = np.asarray(PILImage.open(io.BytesIO(panel.screenshot())).convert("RGB"), dtype=np.float64)
                spread = float(shot.std())
                time.sleep(0.3)
            assert spread > 5.0, "the 3-D panel stayed blank"

            # a click on a recorded pixel selects its rays
            status = page.locator("#warpviz-status")
            assert "nothing selected" in status.inner_text()
            hint = page.locator("#warpviz-hint").inner_text()
            x, y = map(int, re.search(r"\((\d+), (\d+)\)", hint).groups())
            box = image.bounding_box()
            image.click(position={"x": (x + 0.5) * box["width"] / 96, "y": (y + 0.5) * box["height"] / 72})
            page.wait_for_function("!document.querySelector('#warpviz-status').innerText.includes('nothing selected')",
                                   timeout=20_000)  # fmt: skip
            assert re.search(rf"pixel \({x}, {y}\): \d+ geodesic segments", status.inner_text()), status.inner_text()

            # moving the spin slider re-renders the preview (a new picture, the selection cleared)
            before = image.get_attribute("src")
            thumb = page.locator("#warpviz-slider-spin .v-slider-thumb")
            thumb.focus()
            for _ in range(20):
                page.keyboard.press("ArrowLeft")
            _js_src_changed(page, before, 60_000)
            page.wait_for_function("document.querySelector('#warpviz-status').innerText.includes('nothing selected')",
                                   timeout=20_000)  # fmt: skip
            assert page.locator("#warpviz-problem").inner_text() == ""
            assert page.title().startswith("warpviz: "), page.title()  # not trame's default "Trame"
            # every slider shows its value (the thumb label is always on)
            assert page.locator("#warpviz-slider-spin .v-slider-thumb__label").count() == 1
            # and nothing on the page overlaps: the texts, the sliders' values, the picture, the 3-D panel
            boxes = [(sel, page.locator(sel).bounding_box()) for sel in
                     ("#warpviz-image", "#warpviz-status", "#warpviz-hint", "#warpviz-3d")]  # fmt: skip
            labels = page.locator(".v-slider-thumb__label")
            boxes += [(f"slider value {i}", labels.nth(i).bounding_box()) for i in range(labels.count())]
            boxes += [(f"slider {i}", page.locator(".warpviz-slider .v-slider").nth(i).bounding_box())
                      for i in range(page.locator(".warpviz-slider .v-slider").count())]  # fmt: skip
            flat = [(name, (b["x"], b["x"] + b["width"], b["y"], b["y"] + b["height"])) for name, b in boxes if b]
            from warpviz.viewer.layout import overlapping

            own = {(f"slider value {i}", f"slider {i}") for i in range(labels.count())}  # a value on its slider
            clashes = [pair for pair in overlapping(flat) if pair not in own]
            assert clashes == [], clashes
            # and nothing went wrong on the page (the session probe once failed with HTTP 405)
            assert not [c for c in console if c[0] in ("error", "response")], console
        finally:
            browser.close()


# ---------------------------------------------------------------------------------------------- Jupyter


def test_the_web_app_runs_in_a_jupyter_kernel(monkeypatch):
    """In a real kernel: build the app, ``await app.ready``, display it (an iframe of the page), and the
    page answers on its URL while the kernel runs."""
    import urllib.request

    pytest.importorskip("trame")
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")

    nb = nbformat.v4.new_notebook()
    nb.cells = [
        nbformat.v4.new_code_cell("from warpviz.web import TeachingApp\n"
                                  "app = TeachingApp('fig09', preview_width=32, spp=1)\n"
                                  "await app.ready"),
        nbformat.v4.new_code_cell("app"),
        nbformat.v4.new_code_cell("print(app.url, app.renders, app.teaching.status())"),
    ]  # fmt: skip
    monkeypatch.setenv("PYVISTA_OFF_SCREEN", "true")
    monkeypatch.setenv("TRAME_IPYWIDGETS_DISABLE", "1")  # plain HTML output: no widget manager needed
    client = nbclient.NotebookClient(nb, timeout=180, kernel_name="python3")
    with client.setup_kernel():
        for i, cell in enumerate(nb.cells):
            client.execute_cell(cell, i)
        printed = "".join(o.get("text", "") for o in nb.cells[2].outputs)
        url, renders, status = printed.split(" ", 2)
        with urllib.request.urlopen(url.split("?")[0], timeout=30) as page:  # the kernel's loop serves it
            assert page.status == 200 and b"<html" in page.read(2000).lower()
    assert renders == "1" and status.startswith("nothing selected")
    shown = [o for o in nb.cells[1].outputs if o.get("output_type") == "display_data"]
    assert shown and "<iframe" in shown[0]["data"]["text/html"], nb.cells[1].outputs
