"""The live page in a real browser: headless Chromium (the system's, Debian's `chromium`,
driven by Playwright; nothing is downloaded) opens the page a live run serves, drags a
slider with the mouse, and the pull arrives in the simulation (the plant's applied force
and the measured hand wrench); its Stand up and Reset buttons act on the run. The other
live tests set the sliders from Python and so never see the page's own wiring."""

from __future__ import annotations

import os
import shutil
import time

import numpy as np
import pytest
from test_live import _Live, _quick, _world

from drake_standup.sim.live import RESET, SLIDERS, STAND_UP, TOGETHER

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
if CHROMIUM is None:
    # CI installs chromium (.ci/run): there the test must run, not skip.
    if os.environ.get("CI"):
        raise RuntimeError("the browser test needs chromium (apt-get install chromium)")
    pytest.skip("no chromium on this machine", allow_module_level=True)
sync_api = pytest.importorskip("playwright.sync_api")

pytestmark = pytest.mark.slow


def _wait_for(condition, timeout_s: float = 20.0) -> bool:
    """Polls condition() while the page's messages reach Meshcat's server thread."""
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.05)
    return False


@pytest.fixture
def page_and_run():
    live = _Live(_quick())
    live.q0 = live.plant.GetPositions(live.plant_context).copy()  # seated, t = 0
    live.advance(0.1)
    with sync_api.sync_playwright() as playwright:
        browser = playwright.chromium.launch(
            executable_path=CHROMIUM,
            headless=True,
            args=["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader"],
        )
        try:
            page = browser.new_page(viewport={"width": 1200, "height": 800})
            page.goto(live.meshcat.web_url())
            page.get_by_text("Open Controls").click()
            yield page, live
        finally:
            browser.close()


def _control(page, label: str):
    """The page's control row (dat.GUI) whose label is label."""
    return (
        page.locator("li.cr").filter(has=page.locator("span.property-name", has_text=label)).first
    )


def test_a_slider_dragged_in_the_browser_pulls_the_robots_hand(page_and_run):
    page, live = page_and_run
    assert live.meshcat.GetSliderValue(TOGETHER) == 1.0  # the left sliders drive both
    cap = live.scenario.human.reactive.force_cap_N
    np.testing.assert_array_equal(live.measured(), np.zeros((2, 3)))
    # A click at 3/4 of the slider's track: +cap/2 forward (its range is -cap to cap).
    track = _control(page, SLIDERS["left", "fwd"]).locator(".slider")
    box = track.bounding_box()
    page.mouse.click(box["x"] + 0.75 * box["width"], box["y"] + box["height"] / 2)
    name = SLIDERS["left", "fwd"]
    assert _wait_for(lambda: live.meshcat.GetSliderValue(name) != 0.0), "no slider message"
    fwd = live.meshcat.GetSliderValue(name)
    assert fwd == pytest.approx(cap / 2, abs=0.05 * cap)  # where the mouse was
    live.advance(live.step)
    expected = [_world((fwd, 0.0))] * 2
    np.testing.assert_array_equal(live.measured(), expected)
    np.testing.assert_array_equal(live.applied(), expected)


def test_the_pages_stand_up_and_reset_buttons_act_on_the_run(page_and_run):
    page, live = page_and_run
    q0 = live.q0
    live.advance(0.3)
    assert live.output("standup_state")[0] == 1  # trigger: hands, nobody pulls: it waits
    _control(page, STAND_UP).click()
    assert _wait_for(lambda: live.meshcat.GetButtonClicks(STAND_UP) > 0), "no click message"
    live.advance(0.1)
    assert live.output("standup_state")[0] == 2
    live.advance(0.5)
    assert not np.allclose(live.plant.GetPositions(live.plant_context), q0, atol=1e-3)
    _control(page, RESET).click()
    assert _wait_for(lambda: live.meshcat.GetButtonClicks(RESET) > 0), "no click message"
    live.advance(live.step)  # after the chunk the session sees the click and resets
    np.testing.assert_array_equal(live.plant.GetPositions(live.plant_context), q0)
    assert live.output("standup_state")[0] == 1
