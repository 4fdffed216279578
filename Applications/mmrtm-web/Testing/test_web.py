"""mmrtm-web in a real browser: Debian's chromium, headless, driven by
selenium, against the console script started as a user starts it.

Run by ctest with the .venv-vtk96 interpreter (the wheel with its Slicer
classes and trame-slicer installed there), MMRTM_SHARED_DATA_DIR set, and
MMRTM_TEST_OUTPUT_DIR for the screenshot (Documentation/web.md shows it).
"""
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import unittest

from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.keys import Keys

DATA = os.environ["MMRTM_SHARED_DATA_DIR"]
OUTPUT = os.environ.get("MMRTM_TEST_OUTPUT_DIR", os.getcwd())
CHROMIUM, DRIVER = "/usr/bin/chromium", "/usr/bin/chromedriver"

# The 3D view's frame: the largest streamed <img>, drawn into a canvas to
# read its pixels. The background is a vertical gradient, so a pixel is the
# volume's where it differs from the first pixel of its row. Returns
# [width, height, fraction of the volume's pixels, mean brightness, mean
# change from the kept frame (-1 if none of this size), the volume's
# pixels' intersection over union with the kept frame's (-1 if none)], or
# null before the first frame; arguments[0] keeps this frame.
FRAME_STATISTICS = """
const images = Array.from(document.querySelectorAll('img')).filter(i => i.naturalWidth > 0);
if (!images.length) return null;
const img = images.reduce((a, b) => a.naturalWidth * a.naturalHeight >= b.naturalWidth * b.naturalHeight ? a : b);
const canvas = document.createElement('canvas');
const w = img.naturalWidth, h = img.naturalHeight;
canvas.width = w; canvas.height = h;
const context = canvas.getContext('2d');
context.drawImage(img, 0, 0);
const p = context.getImageData(0, 0, w, h).data;
const mask = new Uint8Array(w * h);
const kept = window.mmrtmKeptFrame, keptMask = window.mmrtmKeptMask;
const comparable = kept && kept.length === p.length;
let covered = 0, sum = 0, change = 0, both = 0, either = 0;
for (let y = 0; y < h; y++) {
  const r = 4 * y * w;
  for (let x = 0; x < w; x++) {
    const i = r + 4 * x;
    const d = Math.abs(p[i] - p[r]) + Math.abs(p[i + 1] - p[r + 1]) + Math.abs(p[i + 2] - p[r + 2]);
    mask[y * w + x] = d > 30 ? 1 : 0;
    covered += mask[y * w + x];
    sum += p[i] + p[i + 1] + p[i + 2];
    if (comparable) {
      change += Math.abs(p[i] - kept[i]) + Math.abs(p[i + 1] - kept[i + 1]) + Math.abs(p[i + 2] - kept[i + 2]);
      both += mask[y * w + x] & keptMask[y * w + x];
      either += mask[y * w + x] | keptMask[y * w + x];
    }
  }
}
if (arguments[0]) { window.mmrtmKeptFrame = p; window.mmrtmKeptMask = mask; }
const n = w * h;
return [w, h, covered / n, sum / n / 3, comparable ? change / n / 3 : -1,
        comparable ? both / Math.max(either, 1) : -1];
"""


# The same frame's volume pixels as a string of 0 and 1 (FRAME_STATISTICS'
# rule), to compare two frames in Python.
FRAME_MASK = """
const images = Array.from(document.querySelectorAll('img')).filter(i => i.naturalWidth > 0);
const img = images.reduce((a, b) => a.naturalWidth * a.naturalHeight >= b.naturalWidth * b.naturalHeight ? a : b);
const canvas = document.createElement('canvas');
const w = img.naturalWidth, h = img.naturalHeight;
canvas.width = w; canvas.height = h;
canvas.getContext('2d').drawImage(img, 0, 0);
const p = canvas.getContext('2d').getImageData(0, 0, w, h).data;
const bits = new Array(w * h);
for (let y = 0; y < h; y++) {
  const r = 4 * y * w;
  for (let x = 0; x < w; x++) {
    const i = r + 4 * x;
    bits[y * w + x] = Math.abs(p[i] - p[r]) + Math.abs(p[i + 1] - p[r + 1]) + Math.abs(p[i + 2] - p[r + 2]) > 30 ? '1' : '0';
  }
}
return w + 'x' + h + ':' + bits.join('');
"""


def intersection_over_union(a, b):
    if a.split(":")[0] != b.split(":")[0]:
        return -1.0
    a, b = a.split(":")[1], b.split(":")[1]
    both = sum(1 for x, y in zip(a, b) if x == "1" and y == "1")
    either = sum(1 for x, y in zip(a, b) if x == "1" or y == "1")
    return both / max(either, 1)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class WebViewerTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        for program in (CHROMIUM, DRIVER):
            if not os.path.exists(program):
                raise RuntimeError(program + " is missing: scripts/install-dependencies.sh installs Debian's "
                                   "chromium and chromium-driver")
        os.makedirs(OUTPUT, exist_ok=True)
        cls.port = free_port()
        # A data root of the test's own: two studies, a damaged file, and
        # symbolic links that lead out of it.
        cls.root = tempfile.TemporaryDirectory()
        root = cls.root.name
        for name in ("ct_head_cranium.nrrd", "ct_head_headsq.nrrd"):
            shutil.copy(os.path.join(DATA, name), root)
        with open(os.path.join(DATA, "ct_head_headsq.nrrd"), "rb") as f:
            head = f.read()
        with open(os.path.join(root, "damaged.nrrd"), "wb") as f:
            f.write(head[: len(head) // 3])
        os.symlink(os.path.join(DATA, "ct_head_headsq.nrrd"), os.path.join(root, "link_out.nrrd"))
        os.symlink(os.path.join(DATA, "ct_chest_dicom"), os.path.join(root, "folder_out"))
        script = shutil.which("mmrtm-web", path=os.path.dirname(sys.executable))
        cls.log = open(os.path.join(OUTPUT, "mmrtm-web-test.log"), "w")
        cls.server = subprocess.Popen([script, os.path.join(root, "ct_head_cranium.nrrd"), "--port", str(cls.port)],
                                      stdout=cls.log, stderr=subprocess.STDOUT)
        options = Options()
        for argument in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1200,800"):
            options.add_argument(argument)
        options.binary_location = CHROMIUM
        cls.browser = webdriver.Chrome(service=Service(DRIVER), options=options)

    @classmethod
    def tearDownClass(cls):
        cls.browser.quit()
        cls.server.terminate()
        cls.server.wait(timeout=30)
        cls.log.close()
        cls.root.cleanup()

    def open_page(self):
        """Loads the page once the server answers (it loads the volume first)."""
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline:
            self.assertIsNone(self.server.poll(), "the server exited: see mmrtm-web-test.log")
            try:
                with socket.create_connection(("127.0.0.1", self.port), timeout=1):
                    break
            except OSError:
                time.sleep(0.25)
        start = time.monotonic()
        self.browser.get("http://127.0.0.1:%d/" % self.port)
        return start

    def frame(self, timeout, accept=lambda s: True, keep=False):
        """Statistics of the 3D frame (FRAME_STATISTICS) once `accept` takes
        them; `keep` keeps the frame to measure later frames' change from."""
        deadline, statistics = time.monotonic() + timeout, None
        while time.monotonic() < deadline:
            statistics = self.browser.execute_script(FRAME_STATISTICS, keep)
            if statistics and statistics[0] > 100 and accept(statistics):
                return statistics
            time.sleep(0.1)
        self.fail("no 3D frame within %.0f s (last: %s)" % (timeout, statistics))

    def test_a_the_page_shows_the_path_traced_head_and_a_preset_changes_it(self):
        """The first path-traced frame reaches the browser, shows the head
        (neither empty nor filled), and a preset chosen in the page changes
        the image. Catches a server that never streams our view, a 3D view
        rendered by another method or left black, and a preset menu that
        does not reach the display node."""
        start = self.open_page()
        width, height, coverage, brightness, _, _ = self.frame(60, lambda s: 0.02 < s[2] < 0.95)
        first_frame = time.monotonic() - start
        print("first frame %.1f s after the page was asked for: %d x %d, coverage %.3f, brightness %.1f"
              % (first_frame, width, height, coverage, brightness))
        self.assertGreater(brightness, 5.0, "not a black image")
        time.sleep(3)  # refinement goes on
        self.browser.save_screenshot(os.path.join(OUTPUT, "mmrtm-web.png"))
        # Refinement to its end (or nearly: what it alone changes in a
        # second), then a preset's change.
        deadline = time.monotonic() + 60
        while True:
            self.frame(5, keep=True)
            time.sleep(1)
            refinement = self.frame(5)[4]
            if refinement < 1.0 or time.monotonic() > deadline:
                break
        # Slicer's CT-Muscle preset shows the skin and muscle CT-Bone leaves out.
        self.browser.find_element("css selector", ".preset-select .v-field").click()
        deadline, target, items = time.monotonic() + 10, [], []
        while not target and time.monotonic() < deadline:
            time.sleep(0.2)
            items = self.browser.find_elements("css selector", ".v-list-item")
            target = [i for i in items if i.text.strip() == "CT-Muscle"]
        self.assertTrue(target, "the preset menu lists Slicer's presets: %s" % [i.text for i in items][:8])
        target[0].click()
        clicked = time.monotonic()
        changed = self.frame(20, lambda s: s[4] > max(4.0, 2.5 * refinement))
        print("the preset's image %.2f s after the click: mean change %.1f levels (refinement alone: %.1f)"
              % (time.monotonic() - clicked, changed[4], refinement))


    def message(self):
        messages = self.browser.find_elements("css selector", ".study-message")
        return messages[0].text if messages else ""

    def open_study(self, path):
        """Types `path` into the study field and presses Open; returns the
        page's message once the server has answered: a new message (each
        path's names it, so consecutive ones differ), or "" once the page
        says it shows `path`."""
        before = self.message()
        shown = self.browser.find_element("css selector", ".shown-study")
        field = self.browser.find_element("css selector", ".study-path input")
        field.send_keys(Keys.CONTROL, "a")
        field.send_keys(Keys.DELETE)
        field.send_keys(path, Keys.ENTER)
        time.sleep(0.5)
        self.browser.find_element("css selector", ".open-study").click()
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            time.sleep(0.25)
            now = self.message()
            if now != before and now:
                return now
            if not now and shown.text.strip() == path:
                return ""
        return self.message() or "no answer: the page shows %r" % shown.text

    def test_b_studies_open_from_the_data_root_only(self):
        """Paths that lead out of the data root (`..`, a symbolic link to a
        file or to a folder outside) are refused with a message in the page;
        a damaged file gives a message and the server goes on; a study in
        the root opens and changes the image. Catches a server that opens
        any path it is sent, or dies on bad input."""
        self.open_page()
        self.frame(60, lambda s: 0.02 < s[2] < 0.95, keep=True)
        for path, expected in (("../etc/passwd", "outside the data root"),
                               ("link_out.nrrd", "outside the data root"),
                               ("folder_out", "outside the data root"),
                               ("damaged.nrrd", "could not read")):
            message = self.open_study(path)
            print("%s: %s" % (path, message))
            self.assertIn(expected, message, path)
            self.assertIsNone(self.server.poll(), "the server goes on after " + path)
        self.assertEqual(self.open_study("ct_head_headsq.nrrd"), "", "a study in the data root opens")
        changed = self.frame(30, lambda s: s[4] > 10)
        print("the other study's image: mean change %.1f levels" % changed[4])

    def choose(self, select_class, item):
        """Picks `item` in the page's select `select_class`."""
        self.browser.find_element("css selector", "." + select_class + " .v-field").click()
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:
            items = [i for i in self.browser.find_elements("css selector", ".v-list-item") if i.text.strip() == item]
            if items:
                items[0].click()
                return
            time.sleep(0.2)
        self.fail("no item %s in %s" % (item, select_class))

    def settled_frame(self):
        """The 3D frame once refinement changes it by under a level a
        second (or after a minute), kept for comparisons."""
        deadline = time.monotonic() + 60
        while True:
            self.frame(5, keep=True)
            time.sleep(1)
            if self.frame(5)[4] < 1.0 or time.monotonic() > deadline:
                return self.frame(5, keep=True)

    def test_c_slicers_cpu_ray_cast_covers_the_same_pixels_and_switching_back_converges_again(self):
        """The method menu switches the same volume and preset to Slicer's
        CPU ray cast: its silhouette overlaps ours by at least 0.85 (the
        probe of issue 33 measured 0.932); switching back path traces
        again, to the same silhouette. Catches a 3D view that is not the
        volume (a wrong camera, grid or geometry in our pipeline) and a
        switch back that leaves the new display node without our settings."""
        self.open_page()
        self.frame(60)
        self.assertEqual(self.open_study("ct_head_cranium.nrrd"), "")
        self.choose("preset-select", "CT-Bone")
        ours = self.settled_frame()
        ours_mask = self.browser.execute_script(FRAME_MASK)
        self.choose("method-select", "Slicer's CPU ray cast")
        # VTK's ray cast draws brighter than our unshaded-glow look: its
        # frame is told apart by its brightness, then left to settle.
        self.frame(30, lambda s: abs(s[3] - ours[3]) > 3)
        theirs = self.settled_frame()
        iou = intersection_over_union(ours_mask, self.browser.execute_script(FRAME_MASK))
        print("Slicer's CPU ray cast: coverage %.3f, brightness %.1f; ours %.3f, %.1f; IoU %.3f"
              % (theirs[2], theirs[3], ours[2], ours[3], iou))
        self.browser.save_screenshot(os.path.join(OUTPUT, "mmrtm-web-cpu-ray-cast.png"))
        self.assertGreater(iou, 0.85)
        self.choose("method-select", "Path tracing (MM-RTM)")
        self.frame(30, lambda s: abs(s[3] - ours[3]) < 3)
        back = self.settled_frame()
        iou_back = intersection_over_union(ours_mask, self.browser.execute_script(FRAME_MASK))
        print("path traced again: coverage %.3f, brightness %.1f, IoU with the first %.3f" % (back[2], back[3], iou_back))
        self.assertGreater(iou_back, 0.95, "the same silhouette after switching back")

if __name__ == "__main__":
    unittest.main()
