#!/usr/bin/env python3
"""The operator page in a real browser: Debian's Chromium, headless, driven
by Selenium (chromium-driver), loads the page from a running `camhead run`
on the simulated rig.

    browser_test.py CAMHEAD SOURCE_DIR SCRATCH_DIR

1. The preview changes from one screenshot of it to the next.
2. The lens values the page shows are the run's --record-stats for the
   frame it names (the page shows one frame's record, so they match it
   exactly, to the digits shown).
3. The lens plot has been drawn (its canvas is not blank), and the
   traced-region view, once chosen, is the picture darkened outside the
   region; the calibration-view button names the view saved and the
   command that fits it.
4. On the narrowest phone's screen in use (320x640 CSS pixels) nothing is
   wider than the screen: no sideways scrolling, whatever the length of the
   paths and device names the page shows. If something is, the elements
   that stick out are named.
Screenshots of the whole page are left in SCRATCH_DIR/page.png,
region.png and phone.png.
Prints a line per check, then PASS or FAIL.
"""
import io
import os
import re
import sys
import time

from PIL import Image, ImageChops, ImageStat
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

import web_rig

camhead, source, scratch = sys.argv[1], os.path.abspath(sys.argv[2]), os.path.abspath(sys.argv[3])
os.makedirs(scratch, exist_ok=True)
check = web_rig.Checks()


board = web_rig.write_board(scratch, source, name="browser")
stats = os.path.join(scratch, "browser_stats.jsonl")
options = webdriver.ChromeOptions()
options.binary_location = "/usr/bin/chromium"
for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
             "--window-size=1280,1400", "--user-data-dir=" + os.path.join(scratch, "chromium")):
    options.add_argument(flag)
with web_rig.Run(camhead, board, "--http", "127.0.0.1:0", "--duration", "60",
                 stats=stats) as run:
    run.wait_frames(5)
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
    try:
        driver.set_page_load_timeout(20)
        driver.get(run.url)
        wait = WebDriverWait(driver, 30)
        wait.until(lambda d: d.find_element(By.ID, "frame").text not in ("", "–"))
        wait.until(lambda d: d.execute_script(
            "const i = document.getElementById('preview'); return i.complete && i.naturalWidth > 0"))
        preview = driver.find_element(By.ID, "preview")
        first = Image.open(io.BytesIO(preview.screenshot_as_png)).convert("RGB")
        time.sleep(2)
        second = Image.open(io.BytesIO(preview.screenshot_as_png)).convert("RGB")
        difference = ImageChops.difference(first, second).getbbox()
        check(first.size[0] > 100 and difference is not None,
              "the preview changes between two screenshots 2 s apart (%dx%d)" % first.size)
        shown = driver.execute_script(
            "return ['frame', 'focus', 'iris', 'zoom'].map("
            "(id) => document.getElementById(id).textContent)")
        blank = driver.execute_script(
            "const c = document.getElementById('lens-plot');"
            "const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;"
            "let lit = 0; for (let i = 0; i < d.length; i += 4) if (d[i] + d[i+1] + d[i+2] > 200) ++lit;"
            "return lit")
        check(blank > 100, "the lens plot is drawn (%d bright pixels)" % blank)
        driver.save_screenshot(os.path.join(scratch, "page.png"))
        # The traced-region view: the same picture, darkened where nothing was traced.
        driver.find_element(By.CSS_SELECTOR, "input[name=view][value=region]").click()
        time.sleep(2)
        region = Image.open(io.BytesIO(preview.screenshot_as_png)).convert("L")
        brightness = [ImageStat.Stat(image.convert("L")).mean[0] for image in (second, region)]
        check(driver.find_element(By.ID, "preview").get_attribute("src").endswith("view=region") and
              brightness[1] < 0.8 * brightness[0],
              "the traced-region view is the picture darkened outside the region "
              "(mean %.0f, composite %.0f)" % (brightness[1], brightness[0]))
        driver.save_screenshot(os.path.join(scratch, "region.png"))
        driver.find_element(By.CSS_SELECTOR, "input[name=view][value=composite]").click()
        driver.find_element(By.ID, "capture").click()
        wait.until(lambda d: d.find_element(By.ID, "message").text != "")
        message = driver.find_element(By.ID, "message").text
        check(re.search(r"^view \d+ at focus=\d+", message) and "calibrate camera" in message,
              "the calibration-view button says where the view went and how to fit it: " +
              message)
        driver.set_window_size(320, 640)
        time.sleep(1)
        page, screen, sticking_out = driver.execute_script(
            "const width = document.documentElement.clientWidth, out = [];"
            "for (const e of document.querySelectorAll('body *'))"
            "  if (e.getBoundingClientRect().right > width + 0.5)"
            "    out.push(e.tagName.toLowerCase() + (e.id ? '#' + e.id : '') + ' \"' +"
            "             e.textContent.replace(/\\s+/g, ' ').trim().slice(0, 40) + '\"');"
            "return [document.documentElement.scrollWidth, window.innerWidth, out]")
        check(page <= screen and not sticking_out,
              "on a phone's screen the page is no wider than it (%d <= %d px)%s" %
              (page, screen, "; sticking out: " + ", ".join(sticking_out[:8]) if sticking_out else ""))
        driver.save_screenshot(os.path.join(scratch, "phone.png"))
    finally:
        driver.quit()
frame, focus, iris, zoom = shown
records = {r["output_frame"]: r for r in web_rig.read_stats(stats) if r["kind"] == "composite"}
r = records.get(int(frame))
# Within half the last digit the page shows (and the record's own six digits).
near = lambda text, value, digits: abs(float(text) - value) <= 0.5 * 10 ** -digits + 1e-5 * value
check(r is not None and near(focus, r["focus_m"], 3) and near(iris, r["f_number"], 2) and
      near(zoom, r["focal_length_mm"], 1),
      "the page's frame %s shows focus %s m, f/%s, %s mm: the record's %s" %
      (frame, focus, iris, zoom, r and (r["focus_m"], r["f_number"], r["focal_length_mm"])))
check.finish()
