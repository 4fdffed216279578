"""Benchmark (not a test): a page of mmrtm-web left open while its view
refines, the server's resident memory every 30 s. Prints a line per
sample: seconds since the first frame, resident MiB, the page's
refinement status.

    xvfb-run -a -s "-noreset -screen 0 1024x768x24" \
        .venv-vtk96/bin/python Testing/Benchmarks/soak_web.py [--minutes 15] [--maximum-samples 100000]

Needs the .venv-vtk96 interpreter with the wheel and selenium, Debian's
chromium and chromium-driver, and MMRTM_SHARED_DATA_DIR (default
../shared/data).
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "Applications", "mmrtm-web", "Testing"))
DATA = os.environ.setdefault("MMRTM_SHARED_DATA_DIR", os.path.join(HERE, "..", "..", "..", "shared", "data"))

from test_clients import new_browser, resident_mib  # noqa: E402
from test_web import FRAME_STATISTICS, free_port, printed_address  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=float, default=15)
    parser.add_argument("--maximum-samples", type=int, default=100000)
    parser.add_argument("--study", default=os.path.join(DATA, "ct_head_headsq.nrrd"))
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        log_path = os.path.join(folder, "server.log")
        with open(log_path, "w") as log:
            server = subprocess.Popen([os.path.join(os.path.dirname(sys.executable), "mmrtm-web"), args.study,
                                       "--port", str(free_port()), "--maximum-samples", str(args.maximum_samples)],
                                      stdout=log, stderr=subprocess.STDOUT)
        browser = None
        try:
            address = printed_address(server, log_path)
            browser = new_browser()
            browser.get(address)
            while not (browser.execute_script(FRAME_STATISTICS, False) or [0])[0]:
                time.sleep(0.2)
            start = time.monotonic()
            while time.monotonic() - start < 60 * args.minutes:
                status = browser.find_element("css selector", ".refinement-status").text.split("\n")[0]
                print("%6.0f s  %5.0f MiB  %s" % (time.monotonic() - start, resident_mib(server.pid), status),
                      flush=True)
                time.sleep(30)
        finally:
            if browser is not None:
                browser.quit()
            server.terminate()
            server.wait(timeout=30)


if __name__ == "__main__":
    main()
