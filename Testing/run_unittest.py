#!/usr/bin/env python3
"""Runs unittest names as `python -m unittest -v NAMES` does, from the
current folder, and never reports a skip as a pass: after a line per
skipped test,

    SKIPPED: <test id>: <reason>

it exits with 77 (the tests' SKIP_RETURN_CODE in CTest) when every test
that ran passed but some were skipped; 1 when one failed. CI then fails on
any skip that Testing/allowed-skips.txt does not list with its reason
(Testing/check_skips.py)."""

import os
import sys
import unittest

SKIP = 77

if __name__ == "__main__":
    sys.path.insert(0, os.getcwd())
    suite = unittest.defaultTestLoader.loadTestsFromNames(sys.argv[1:])
    result = unittest.TextTestRunner(verbosity=2).run(suite)
    for test, reason in result.skipped:
        print(f"SKIPPED: {test.id()}: {reason}", flush=True)
    if not result.wasSuccessful() or result.testsRun == 0:
        sys.exit(1)
    sys.exit(SKIP if result.skipped else 0)
