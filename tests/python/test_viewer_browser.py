"""The browser viewer in a real browser: Debian's headless Chromium (WebGL through SwiftShader, on the CPU)
driven by selenium opens /view/<scene> on the real server and we look at the pixels it drew.

Chromium and chromedriver come from deploy/install-deps.sh (chromium, chromium-driver); selenium from the
client's test extra. Waits are generous: SwiftShader on a loaded 2-core machine draws a frame in tens of ms
to seconds, and the first start of Chromium takes several seconds.
"""
import io
import shutil
import time

import numpy as np
import pytest

import graspsim

CHROMIUM, CHROMEDRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"
WAIT_S = 60.0
CUBE = 0.05        # m
TABLE_TOP = 0.75   # m, built-in table
BASE_Z = 1.05      # m, the PG70 cell's axis base (as tests/python/test_work_cycle.py)


@pytest.fixture(scope="module")
def browser():
    webdriver = pytest.importorskip("selenium.webdriver")
    from selenium.webdriver.chrome.service import Service

    for path in (CHROMIUM, CHROMEDRIVER):
        if not shutil.which(path):
            pytest.fail(f"{path} missing: run deploy/install-deps.sh (Debian packages chromium, chromium-driver)",
                        pytrace=False)
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader", "--window-size=1000,700", "--force-device-scale-factor=1"):
        options.add_argument(arg)
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    driver.set_page_load_timeout(WAIT_S)
    yield driver
    driver.quit()


def wait_for(driver, script: str, what: str, timeout: float = WAIT_S):
    """Polls a JavaScript expression until it is truthy; returns its value."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = driver.execute_script(f"return {script}")
        if value:
            return value
        time.sleep(0.1)
    state = driver.execute_script("return window.graspsimViewer && window.graspsimViewer.state")
    pytest.fail(f"timed out after {timeout} s waiting for {what}; viewer state: {state}", pytrace=False)


def open_viewer(driver, server, scene_id: str):
    driver.get(graspsim.viewer_url(scene_id, server.http_url))
    wait_for(driver, "window.graspsimViewer && window.graspsimViewer.state.ready && window.graspsimViewer.state.snapshots > 0",
             "the viewer to load the scene and its first snapshot")
    error = driver.execute_script("return window.graspsimViewer.state.error")
    assert error is None, error


def pixel(driver, x: float, y: float):
    from PIL import Image

    image = Image.open(io.BytesIO(driver.get_screenshot_as_png())).convert("RGB")
    return image.getpixel((int(round(x)), int(round(y))))


def is_cube_orange(rgb) -> bool:
    """The page draws free bodies orange (0xe0913a, shaded): red well above green and blue. The background
    (0x1d2024), the grid's greys and the static bodies' grey are not."""
    r, g, b = rgb
    return r > g + 25 and r > b + 50


def test_canvas_draws_the_cube_and_follows_a_pose_change(browser, server, client, scene_id):
    client.add_object(scene_id, "cube", box=(CUBE, CUBE, CUBE), mass=0.1, pose=[0, 0, CUBE / 2, 1, 0, 0, 0])
    open_viewer(browser, server, scene_id)
    where = browser.execute_script("return window.graspsimViewer.bodyScreenPosition('cube')")
    # Let a few frames draw, then look where the cube's centre projects.
    time.sleep(1.0)
    before = pixel(browser, where["x"], where["y"])
    assert is_cube_orange(before), f"pixel {before} at the cube's centre {where} is not the cube's colour"
    corner = pixel(browser, 5, browser.execute_script("return window.innerHeight") - 5)  # far from the cube
    assert not is_cube_orange(corner)

    revision = client.set_body_pose(scene_id, "cube", [-0.08, 0, CUBE / 2, 1, 0, 0, 0])
    wait_for(browser, f"window.graspsimViewer.state.lastSnapshot.revision >= {revision}", "the moved pose")
    moved = browser.execute_script("return window.graspsimViewer.bodyScreenPosition('cube')")
    assert abs(moved["x"] - where["x"]) + abs(moved["y"] - where["y"]) > 20, (where, moved)
    time.sleep(1.0)
    at_new, at_old = pixel(browser, moved["x"], moved["y"]), pixel(browser, where["x"], where["y"])
    assert is_cube_orange(at_new), f"pixel {at_new} at the moved cube {moved}"
    assert not is_cube_orange(at_old), f"pixel {at_old} where the cube was {where} still shows it"
    # Geometry came once; only poses followed.
    state = browser.execute_script("return window.graspsimViewer.state")
    assert state["sceneFetches"] == 1 and state["snapshots"] >= 2


def test_a_new_body_is_fetched_and_drawn(browser, server, client, scene_id):
    client.add_object(scene_id, "cube", box=(CUBE, CUBE, CUBE), mass=0.1, pose=[0, 0, CUBE / 2, 1, 0, 0, 0])
    open_viewer(browser, server, scene_id)
    client.add_object(scene_id, "ball", sphere=0.02, mass=0.1, pose=[0.06, 0.06, 0.02, 1, 0, 0, 0])
    wait_for(browser, "window.graspsimViewer.state.bodyIds.includes('ball')", "the new body's geometry")
    assert browser.execute_script("return window.graspsimViewer.state.sceneFetches") == 2
    where = wait_for(browser, "window.graspsimViewer.bodyScreenPosition('ball')", "the ball on screen")
    time.sleep(1.0)
    assert is_cube_orange(pixel(browser, where["x"], where["y"]))


def test_tactile_heat_map_appears_during_a_work_cycle(browser, server, client, scene_id):
    """The pads' panels draw pressure at a simulation time inside the cycle's grasp. Judged in simulation time:
    a cycle may run many times faster than real time, so the page's strongest reading is kept, not polled."""
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
    client.add_robot(scene_id, "cell", builtin="schunk_pg70_on_z_axis", base_pose=[0, 0, BASE_Z, 1, 0, 0, 0])
    pads = [a.id for a in client.get_scene(scene_id).tactile_arrays]
    open_viewer(browser, server, scene_id)
    before = browser.execute_script("return window.graspsimViewer.state.pads.stats()")
    assert sorted(before) == sorted(pads) and all(p["peakIntensity"] == 0 for p in before.values())  # open pads

    # A long hold (20 s simulated) gives the 10 Hz tactile stream many readings while the pads press.
    result = client.run_work_cycle(scene_id, "cell", "cube", hold_time=20.0, timeout=600)
    stats = wait_for(browser, "(() => { const s = window.graspsimViewer.state.pads.stats();"
                              " return Object.values(s).every((p) => p.peakIntensity > 0) && s; })()",
                     "pressure on both pads")
    pressed = result.time[(result.left_sum > 0) | (result.right_sum > 0)]
    for pad in pads:
        assert pressed.min() - 0.05 <= stats[pad]["peakTime"] <= pressed.max() + 0.05, (pad, stats[pad], pressed[[0, -1]])
        assert stats[pad]["peakRed"] > 0  # the heat map's pixels show it


def test_contact_overlay_shows_the_steps_contacts(browser, server, client, scene_id):
    client.set_simulation_params(scene_id, sleep_time=100.0)  # a sleeping body's contacts are not computed
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
    client.step_simulation(scene_id, 0.5)
    with client.watch_scene(scene_id) as watch:
        expected = len(next(iter(watch)).contacts)
    assert expected >= 4
    open_viewer(browser, server, scene_id)
    wait_for(browser, f"window.graspsimViewer.state.contacts === {expected}", f"{expected} contacts drawn")
    legend = browser.find_element("id", "contact-legend").text
    assert legend.startswith(f"{expected} contact points; largest force ")
    browser.find_element("id", "show-contacts").click()  # off: the page asks for poses without contacts
    revision = client.set_body_pose(scene_id, "cube", [0, 0, 0.9, 1, 0, 0, 0])
    wait_for(browser, f"window.graspsimViewer.state.lastSnapshot.revision >= {revision}", "the pose without contacts")
    assert browser.execute_script("return window.graspsimViewer.state.contacts") == expected  # not updated while off


def test_planned_grasps_are_listed_best_first(browser, server, client, scene_id):
    client.add_object(scene_id, "table", builtin="table")
    client.add_object(scene_id, "cube", builtin="cube_5cm", pose=[0, 0, TABLE_TOP + CUBE / 2, 1, 0, 0, 0])
    planned = client.plan_grasps("schunk_pg70", scene_id=scene_id, body_id="cube", spacing=0.02, max_grasps=5,
                                 progress=False, timeout=600)
    assert len(planned.grasps) > 0
    browser.get(graspsim.viewer_url(scene_id, server.http_url, grasp_set=planned.set_id, grasp_object="cube"))
    wait_for(browser, "window.graspsimViewer && window.graspsimViewer.state.ready", "the viewer with the grasp set")
    assert browser.execute_script("return window.graspsimViewer.state.error") is None
    items = [li.text for li in browser.find_elements("css selector", "#grasps li")]
    assert len(items) == len(planned.grasps)
    shown = [float(text.split("ε = ")[1].split(" ")[0]) for text in items]
    np.testing.assert_allclose(shown, planned.grasps["epsilon"], atol=5e-5)  # printed to 4 decimals, best first


def test_an_arm_path_planned_while_watching_is_drawn(browser, server, client, scene_id):
    """The page picks up a PlanArmPath made after it opened (polled overlays.json) and shows its row."""
    client.add_object(scene_id, "table", builtin="table")
    client.add_robot(scene_id, "pa10", builtin="mitsubishi_pa10_pg70", base_pose=[-0.45, 0, 0.75, 1, 0, 0, 0])
    open_viewer(browser, server, scene_id)
    assert browser.execute_script("return window.graspsimViewer.state.overlays.armPathPoints") == 0
    path = client.plan_arm_path(scene_id, "pa10", goal=[0.1, -0.1, 1.05, 0, 1, 0, 0])
    points = wait_for(browser, "window.graspsimViewer.state.overlays.armPathPoints", "the arm path drawn")
    assert points == 1 + 8 * (path.waypoints.shape[0] - 1)
    rows = browser.execute_script("return [...document.querySelectorAll('#overlays label')]"
                                  ".filter((r) => !r.hidden).map((r) => r.textContent)")
    assert any("Arm path" in row and "pa10" in row for row in rows)
