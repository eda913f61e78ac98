#!/usr/bin/python3
"""The browser viewer in a real browser: headless Chromium driven by Selenium against a real
daemon. Loads the page, creates a session from the panel, sees the live MJPEG view, starts an
evolution and sees its progress reach 100 % and the view's image change, and sees a bad
formula's error with a caret under its column.

Usage: viewer_browser.py LEVELSETD SCRATCH_DIR
"""
import os
import shutil
import sys
import time

from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service as ChromeService
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from daemon_harness import Daemon, write_sphere_cloud  # noqa: E402

BIN, SCRATCH = sys.argv[1], sys.argv[2]
shutil.rmtree(SCRATCH, ignore_errors=True)
os.makedirs(SCRATCH)


def check(cond, what):
    if not cond:
        raise AssertionError(what)


options = Options()
options.binary_location = "/usr/bin/chromium"
for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1400,900"):
    options.add_argument(arg)
d = Daemon(BIN, os.path.join(SCRATCH, "data"))
driver = webdriver.Chrome(service=ChromeService("/usr/bin/chromedriver"), options=options)
wait = WebDriverWait(driver, 60)
try:
    driver.get(d.url + "/")
    check(driver.title == "levelsetd viewer", f"page title: {driver.title}")
    # A session from the panel; it appears in the list, selected.
    driver.find_element(By.ID, "shape").send_keys("torus")
    res = driver.find_element(By.ID, "resolution")
    res.clear()
    res.send_keys("48")
    driver.find_element(By.ID, "create").click()
    wait.until(lambda _: driver.find_elements(By.CSS_SELECTOR, "#sessions li.selected"))
    sessions = d.get("/api/v1/sessions")[2]["sessions"]
    check(len(sessions) == 1, f"one session created: {sessions}")
    # The live view: the MJPEG stream draws the session.
    wait.until(lambda _: driver.execute_script("return document.getElementById('stream').naturalWidth") == 800)
    before = driver.find_element(By.ID, "stream").screenshot_as_png
    # An evolution: its card's progress reaches 100 % and the job succeeds.
    formula = driver.find_element(By.ID, "formula")
    formula.clear()
    formula.send_keys("-(k1+k2)")
    steps = driver.find_element(By.ID, "steps")
    steps.clear()
    steps.send_keys("40")
    driver.find_element(By.ID, "start").click()
    wait.until(lambda _: driver.find_elements(By.CSS_SELECTOR, ".job .state"))
    wait.until(lambda _: driver.find_element(By.CSS_SELECTOR, ".job .state").text == "succeeded")
    pct = driver.find_element(By.CSS_SELECTOR, ".job .pct").text
    width = driver.find_element(By.CSS_SELECTOR, ".job .bar > div").get_attribute("style")
    check(pct == "100 %" and "100%" in width, f"progress at the end: {pct}, {width}")
    check(d.get(f"/api/v1/sessions/{sessions[0]['id']}")[2]["version"] == 2, "the job committed version 2")
    # The stream shows the evolved surface: the view's image changed.
    wait.until(lambda _: driver.find_element(By.ID, "stream").screenshot_as_png != before)
    # A bad formula: the server's error, with the caret under the column it names.
    formula.clear()
    formula.send_keys("1 + * k1")
    driver.find_element(By.ID, "start").click()
    wait.until(lambda _: driver.find_element(By.ID, "formula-error").text.strip())
    lines = driver.find_element(By.ID, "formula-error").text.split("\n")
    check(lines[0] == "1 + * k1" and lines[1].index("^") == 4, f"formula error: {lines}")
    check(driver.find_element(By.ID, "view-message").text == "", "no error over the view")
    # Display settings become the session's view (PUT .../view) and the stream follows them.
    sid = sessions[0]["id"]
    shown = driver.find_element(By.ID, "stream").screenshot_as_png
    driver.find_element(By.ID, "shading").send_keys("wireframe")
    driver.find_element(By.CSS_SELECTOR, "[data-view=boundary]").click()
    wait.until(lambda _: d.get(f"/api/v1/sessions/{sid}/view")[2].get("boundary") is True)
    stored = d.get(f"/api/v1/sessions/{sid}/view")[2]
    check(stored["shading"] == "wireframe" and stored["cloud"]["on"] is True, f"stored view: {stored}")
    wait.until(lambda _: driver.find_element(By.ID, "stream").screenshot_as_png != shown)
    # The region of influence: stored from the page, shown through the view's roi setting.
    driver.find_element(By.ID, "store-roi").click()
    wait.until(lambda _: isinstance(d.get(f"/api/v1/sessions/{sid}")[2].get("roi"), dict))
    wait.until(lambda _: "voxels" in driver.find_element(By.ID, "roi-info").text)
    driver.find_element(By.CSS_SELECTOR, "[data-view=roi]").click()
    wait.until(lambda _: (d.get(f"/api/v1/sessions/{sid}/view")[2].get("roi") or {}).get("on") is True)
    driver.find_element(By.ID, "clear-roi").click()
    wait.until(lambda _: d.get(f"/api/v1/sessions/{sid}")[2].get("roi") is None)
    wait.until(lambda _: driver.find_element(By.ID, "roi-info").text == "")
    # A point cloud from this computer: uploaded, reconstructed into a session that shows it.
    cloud = write_sphere_cloud(os.path.join(SCRATCH, "ball.xyz"), 4000)
    driver.find_element(By.ID, "file").send_keys(cloud)
    res = driver.find_element(By.ID, "upload-resolution")
    res.clear()
    res.send_keys("48")
    driver.execute_script("current = null")  # as on a fresh page: nothing selected
    driver.find_element(By.ID, "upload").click()
    wait.until(lambda _: len(d.get("/api/v1/sessions")[2]["sessions"]) == 2)
    made = [s for s in d.get("/api/v1/sessions")[2]["sessions"] if s["id"] != sid][0]
    check(made["name"] == "ball.xyz" and made["points"]["points"] == 4000, f"the uploaded session keeps its points: {made}")
    wait.until(lambda _: driver.execute_script("return current") == made["id"])
    check(driver.find_element(By.ID, "session-error").text == "", "no upload error")
    driver.save_screenshot(os.path.join(SCRATCH, "viewer.png"))
finally:
    driver.quit()
    d.stop()
print("viewer_browser: the page created a session, streamed it, ran a job to 100 % with the view changing, showed a "
      "formula error at its column, steered the display, and made a session from an uploaded point cloud")
