"""Benchmark (not a test): mmrtm-web in headless Chromium, its streaming
(one frame per sample pass) against trame-rca's own scheduler, each in a
server of its own, one after the other in this run. Prints per scheduler:
the time from asking for the page to the first 3D frame and to the first
at the view's size, the time to the maximum samples (the toolbar saying
converged), the frames the browser received on the way and the passes,
a camera drag's first preview after the first move and its frames a
second, the time to converge again after it, and the server's memory
(resident before a browser connects, and at its peak) and the cores it
keeps busy before a browser connects.

    .venv-vtk96/bin/python Testing/Benchmarks/bench_web.py [--maximum-samples 64] [--study PATH]

Needs the .venv-vtk96 interpreter with the wheel and selenium, Debian's
chromium and chromium-driver, and MMRTM_SHARED_DATA_DIR (default
../shared/data). Runs under xvfb-run or headless (EGL).
"""
import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "Applications", "mmrtm-web", "Testing"))
DATA = os.environ.setdefault("MMRTM_SHARED_DATA_DIR", os.path.join(HERE, "..", "..", "..", "shared", "data"))

from selenium import webdriver  # noqa: E402
from selenium.webdriver.chrome.options import Options  # noqa: E402
from selenium.webdriver.chrome.service import Service  # noqa: E402
from selenium.webdriver.common.action_chains import ActionChains  # noqa: E402

from test_web import CHROMIUM, DRIVER, FRAME_STATISTICS, RECORDER, free_port, printed_address  # noqa: E402


def cpu_seconds(pid):
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def memory_mib(pid, field):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024
    return float("nan")


class Session:
    """A server with one scheduler, and a browser on its page."""

    def __init__(self, study, streaming, maximum_samples):
        self.port = free_port()
        script = shutil.which("mmrtm-web", path=os.path.dirname(sys.executable))
        self.log = tempfile.NamedTemporaryFile()
        self.server = subprocess.Popen([script, study, "--port", str(self.port), "--streaming", streaming,
                                        "--maximum-samples", str(maximum_samples)],
                                       stdout=self.log, stderr=subprocess.STDOUT)
        self.address = printed_address(self.server, self.log.name)
        # What it does before any browser connects.
        time.sleep(1)
        cpu = cpu_seconds(self.server.pid)
        time.sleep(3)
        self.cpu_before = (cpu_seconds(self.server.pid) - cpu) / 3
        self.resident_before = memory_mib(self.server.pid, "VmRSS")
        options = Options()
        for argument in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1200,800"):
            options.add_argument(argument)
        options.binary_location = CHROMIUM
        self.browser = webdriver.Chrome(service=Service(DRIVER), options=options)

    def close(self):
        self.browser.quit()
        self.server.terminate()
        self.server.wait(timeout=30)

    def statistics(self):
        return self.browser.execute_script(FRAME_STATISTICS, False)

    def status(self):
        text = self.browser.find_element("css selector", ".refinement-status").text
        samples, maximum = text.split(" samples")[0].split(" / ")
        return int(samples), int(maximum), "(converged)" in text

    def loads(self):
        loads = self.browser.execute_script("return window.mmrtmLoads") or []
        largest = max((area for _, area in loads), default=0)
        return [t for t, area in loads if area == largest]

    def wait(self, condition, timeout, poll=0.02):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                if condition():
                    return time.monotonic()
            except Exception:  # the page may still be building
                pass
            time.sleep(poll)
        return float("nan")

    def converged(self, maximum_samples):
        samples, _, converged = self.status()
        return converged and samples >= maximum_samples


def measure(study, streaming, maximum_samples):
    session = Session(study, streaming, maximum_samples)
    try:
        browser = session.browser
        asked, asked_epoch = time.monotonic(), time.time()
        browser.get(session.address)
        browser.execute_script(RECORDER)
        first = session.wait(lambda: session.statistics() and session.statistics()[0] > 100, 60)
        # Polled slowly: the browser's work would take the server's cores.
        converged = session.wait(lambda: session.converged(maximum_samples), 300, poll=0.25)
        time.sleep(1)
        received = len(session.loads())
        # The first frame at the view's size: the first of the largest
        # frames, on the page's clock (from its navigation).
        at_size = session.loads()[0] / 1000 + browser.execute_script(
            "return performance.timeOrigin") / 1000 - asked_epoch
        # The drag: 40 moves 50 ms apart, as a hand turns a head.
        view = browser.execute_script(
            "return Array.from(document.querySelectorAll('img')).filter(i => i.naturalWidth > 0)"
            ".reduce((a, b) => a.naturalWidth * a.naturalHeight >= b.naturalWidth * b.naturalHeight ? a : b)")
        mouse, loads = len(browser.execute_script("return window.mmrtmMouse")), len(session.loads())
        drag = ActionChains(browser, duration=0).move_to_element(view).click_and_hold()
        for _ in range(40):
            drag.move_by_offset(5, 0).pause(0.05)
        drag.release().perform()
        released_at = time.monotonic()
        time.sleep(0.5)
        events = browser.execute_script("return window.mmrtmMouse")[mouse:]
        moves = [t for kind, t in events if kind == "move"]
        released = [t for kind, t in events if kind == "up"][-1]
        during = [t for t in session.loads()[loads:] if moves[0] <= t <= released]
        again = session.wait(lambda: session.converged(maximum_samples), 300, poll=0.25)
        return {
            "first frame s": first - asked,
            "first at view size s": at_size,
            "to %d spp s" % maximum_samples: converged - asked,
            "frames received to it": received,
            "passes to it": maximum_samples // 4,
            "drag: first preview s": (during[0] - moves[0]) / 1000 if during else float("nan"),
            "drag: frames a second": len(during) / ((released - moves[0]) / 1000),
            "drag: median frame gap s": statistics.median(b - a for a, b in zip(during, during[1:])) / 1000
            if len(during) > 1 else float("nan"),
            "converged again after release s": again - released_at,
            "server CPU before a browser (cores)": session.cpu_before,
            "server MiB before a browser": session.resident_before,
            "server peak MiB": memory_mib(session.server.pid, "VmHWM"),
        }
    finally:
        session.close()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--study", default=os.path.join(DATA, "ct_head_cranium.nrrd"))
    parser.add_argument("--maximum-samples", type=int, default=64)
    args = parser.parse_args()
    results = {streaming: measure(args.study, streaming, args.maximum_samples)
               for streaming in ("progressive", "trame-rca")}
    print("%-36s %12s %12s %8s" % ("", "progressive", "trame-rca", "ratio"))
    for key in results["progressive"]:
        ours, theirs = results["progressive"][key], results["trame-rca"][key]
        print("%-36s %12.3f %12.3f %8.2f" % (key, ours, theirs, ours / theirs if theirs else float("nan")))


if __name__ == "__main__":
    main()
