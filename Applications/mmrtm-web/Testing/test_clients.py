"""Several browsers on one mmrtm-web server: each sees the same study and
view, any may drive it, and none that leaves (however it leaves) stops the
others.

Run by ctest (vtk96-web-clients) with the .venv-vtk96 interpreter,
MMRTM_SHARED_DATA_DIR set, and Debian's chromium and chromium-driver.

What it can catch: a second browser that gets no frames or takes the view
from the first; a disconnect mid-pass, mid-drag or by reload that stops
the refinement the first browser watches (its sample count stops rising),
crashes the server or leaves it rendering previews; a page opened twice in
one browser that breaks either; memory that grows with each connect and
leave (50 cycles, the growth bound below); the page's maximum samples,
raised, throwing the converged view's samples away.
"""
import os
import re
import subprocess
import sys
import tempfile
import time
import unittest

from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.keys import Keys

from test_web import CHROMIUM, DRIVER, FRAME_STATISTICS, free_port, printed_address

DATA = os.environ["MMRTM_SHARED_DATA_DIR"]
# Far more samples than the test takes, so that the first browser's view
# refines all along.
MAXIMUM_SAMPLES = 100000
CYCLES = 50
# Resident memory the server may gain over the 50 connect/leave cycles
# (after 5 first cycles that fill its caches), its view at rest: measured
# +1 MiB; a leak of half a frame buffer per connection (the view's RGBA
# frame is about 1 MiB) would pass 25.
CYCLE_GROWTH_BOUND_MIB = 25.0


def resident_mib(pid):
    with open("/proc/%d/status" % pid) as f:
        return int(re.search(r"^VmRSS:\s+(\d+)", f.read(), re.MULTILINE).group(1)) / 1024


def new_browser():
    options = Options()
    for argument in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1000,700"):
        options.add_argument(argument)
    options.binary_location = CHROMIUM
    return webdriver.Chrome(service=Service(DRIVER), options=options)


class SharedServerTest(unittest.TestCase):
    """A server refining to `maximum_samples`, and a first browser on it."""
    maximum_samples = MAXIMUM_SAMPLES

    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.TemporaryDirectory()
        cls.log_path = os.path.join(cls.folder.name, "server.log")
        with open(cls.log_path, "w") as log:
            script = os.path.join(os.path.dirname(sys.executable), "mmrtm-web")
            cls.server = subprocess.Popen([script, os.path.join(DATA, "ct_head_headsq.nrrd"), "--port",
                                           str(free_port()), "--maximum-samples", str(cls.maximum_samples)],
                                          stdout=log, stderr=subprocess.STDOUT)
        cls.address = printed_address(cls.server, cls.log_path)
        cls.first = new_browser()
        cls.first.get(cls.address)

    @classmethod
    def tearDownClass(cls):
        cls.first.quit()
        cls.server.terminate()
        cls.server.wait(timeout=30)
        cls.folder.cleanup()

    def frame(self, browser, timeout=90):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            statistics = browser.execute_script(FRAME_STATISTICS, False)
            if statistics and statistics[0] > 100 and statistics[2] > 0.02:
                return statistics
            time.sleep(0.25)
        self.fail("no 3D frame of the study within %.0f s" % timeout)

    def samples(self, browser):
        text = browser.find_element("css selector", ".refinement-status").text
        found = re.match(r"\s*(\d+) / \d+ samples", text)
        return int(found.group(1)) if found else 0

    def assertRefining(self, why, restarted=False, timeout=60):
        """The first browser's sample count rises by two passes within
        `timeout`, without starting again unless the view `restarted`
        (turned, or resized), and the server is alive."""
        self.assertIsNone(self.server.poll(), "the server exited (%s): see %s" % (why, self.log_path))
        self.frame(self.first)
        start = self.samples(self.first)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            now = self.samples(self.first)
            if now < start:
                self.assertTrue(restarted, "the first browser's refinement started again after %s (samples %d -> %d)"
                                % (why, start, now))
                start = now
            elif now >= start + 8:
                return now
            time.sleep(0.5)
        self.fail("the first browser's view stopped refining after %s (samples %d -> %d)"
                  % (why, start, self.samples(self.first)))

    def drag(self, browser, step, moves=5, release=False):
        """A drag in `browser`'s 3D view of `moves` moves by `step` (x, y)
        pixels 50 ms apart, the button left held unless `release`."""
        drag = ActionChains(browser, duration=0).move_to_element(self.view(browser)).click_and_hold()
        for _ in range(moves):
            drag.move_by_offset(*step).pause(0.05)
        (drag.release() if release else drag).perform()

    def view(self, browser):
        return browser.execute_script(
            "return Array.from(document.querySelectorAll('img')).filter(i => i.naturalWidth > 0)"
            ".reduce((a, b) => a.naturalWidth * a.naturalHeight >= b.naturalWidth * b.naturalHeight ? a : b)")



class ClientsTest(SharedServerTest):
    """Browsers that come, drive and leave while the first one watches the
    view refine."""

    def test_a_a_second_browser_sees_the_view_and_leaves_the_first_refining(self):
        self.assertRefining("the first browser opened the page")
        second = new_browser()
        try:
            second.get(self.address)
            first, other = self.frame(self.first), self.frame(second)
            self.assertEqual(first[:2], other[:2], "the same view's size")
            self.assertRefining("a second browser connected")
        finally:
            second.quit()
        self.assertRefining("the second browser left")

    def test_b_any_browser_drives_the_shared_view(self):
        second = new_browser()
        try:
            second.get(self.address)
            self.frame(second)
            time.sleep(2)
            self.first.execute_script(FRAME_STATISTICS, True)  # kept: the frame the others are compared with
            time.sleep(2)
            refined = self.first.execute_script(FRAME_STATISTICS, False)
            # A vertical drag: the head seen from above, its outline another.
            self.drag(second, (0, 15), moves=10, release=True)
            time.sleep(3)
            turned = self.first.execute_script(FRAME_STATISTICS, False)
            print("the first browser's view: 2 s of refinement changed it by %.1f levels (outline IoU %.3f), the "
                  "second browser's drag by %.1f (IoU %.3f)" % (refined[4], refined[5], turned[4], turned[5]))
            self.assertLess(turned[5], 0.8, "the second browser's drag turned the first browser's view")
        finally:
            second.quit()
        self.assertRefining("the driving browser left", restarted=True)

    def test_c_leaving_mid_drag_by_quitting_or_reloading_leaves_the_others_working(self):
        second = new_browser()
        try:
            second.get(self.address)
            self.frame(second)
            self.drag(second, (10, 0))  # the button is still held
            second.refresh()
            self.frame(second)
            self.assertRefining("a reload in the middle of a drag", restarted=True)
            self.drag(second, (-10, 0))
        finally:
            second.quit()  # in the middle of the drag
        self.assertRefining("a browser that quit in the middle of a drag", restarted=True)

    def test_d_a_page_opened_twice_in_one_browser(self):
        second = new_browser()
        try:
            second.get(self.address)
            self.frame(second)
            first_tab = second.current_window_handle
            second.switch_to.new_window("tab")
            second.get(re.sub(r"\?token=.*$", "", self.address))  # the cookie, as a second tab has it
            self.frame(second)
            second.close()
            second.switch_to.window(first_tab)
            self.frame(second)
            self.assertRefining("a second tab closed")
        finally:
            second.quit()


class CyclesTest(SharedServerTest):
    """Fifty browsers come and go while the first one watches a view at
    rest (converged: the memory measured is the connections' own); then
    the page's maximum samples is raised."""
    maximum_samples = 16

    def status(self):
        return self.first.find_element("css selector", ".refinement-status").text.split("\n")[0]

    def test_a_connecting_and_leaving_fifty_times(self):
        self.frame(self.first)
        deadline = time.monotonic() + 120
        while "(converged)" not in self.status() and time.monotonic() < deadline:
            time.sleep(0.5)
        converged = self.status()
        self.assertIn("(converged)", converged)
        second = new_browser()
        base = re.sub(r"\?token=.*$", "", self.address)
        try:
            second.get(self.address)
            for cycle in range(CYCLES + 5):
                if cycle == 5:
                    resident_before = resident_mib(self.server.pid)
                second.get(base)
                self.frame(second, timeout=30)
                second.get("about:blank")
                self.assertIsNone(self.server.poll(), "the server exited at cycle %d" % cycle)
            time.sleep(1)
            resident_after = resident_mib(self.server.pid)
        finally:
            second.quit()
        print("%d connect/leave cycles: the server's resident memory %.0f -> %.0f MiB; the first browser's status "
              "'%s' -> '%s'" % (CYCLES, resident_before, resident_after, converged, self.status()))
        self.assertLess(resident_after - resident_before, CYCLE_GROWTH_BOUND_MIB)
        self.assertEqual(self.status(), converged, "the converged view kept, not started again")

    def test_b_a_higher_maximum_goes_on_from_the_samples_shown(self):
        """The page's maximum samples raised on a converged view: the
        refinement goes on from its samples (a restart would show fewer)."""
        self.frame(self.first)
        deadline = time.monotonic() + 120
        while "(converged)" not in self.status() and time.monotonic() < deadline:
            time.sleep(0.5)
        converged = self.samples(self.first)
        field = self.first.find_element("css selector", ".maximum-samples input")
        field.send_keys(Keys.CONTROL, "a")
        field.send_keys(str(converged + 8))
        fewest, deadline = converged, time.monotonic() + 60
        while time.monotonic() < deadline and not self.status().startswith("%d / %d" % ((converged + 8,) * 2)):
            fewest = min(fewest, self.samples(self.first))
            time.sleep(0.1)
        print("maximum %d -> %d: the samples shown went %d -> %s (fewest %d)"
              % (converged, converged + 8, converged, self.status(), fewest))
        self.assertTrue(self.status().startswith("%d / %d" % ((converged + 8,) * 2)), self.status())
        self.assertEqual(fewest, converged, "never started again")


if __name__ == "__main__":
    unittest.main()
