#!/usr/bin/env python3
"""Fails when a test was skipped for a reason Testing/allowed-skips.txt does
not list: CI's rule that a skip is never a silent pass (.ci/run).

    check_skips.py CTEST_JUNIT_XML [ALLOWED_SKIPS]

CTEST_JUNIT_XML: what `ctest --output-junit` wrote. Skipped tests are those
CTest did not run or marked skipped (GTEST_SKIP, SKIP_RETURN_CODE 77 from
Testing/run_unittest.py or a script, a DISABLED_ GoogleTest test); each
skip's reason is read from its output (gtest's "Skipped" message,
"SKIPPED: ..." lines; "disabled" for a disabled test). A skip passes only
if a line of ALLOWED_SKIPS matches both its test name and its reason.
"""

import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path


def allowed_rules(path):
    rules = []
    for number, line in enumerate(Path(path).read_text().splitlines(), 1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        parts = [p.strip() for p in line.split(" | ")]
        if len(parts) != 3 or not all(parts):
            sys.exit(f"{path}:{number}: expected 'test name regex | reason regex | why'")
        rules.append((re.compile(parts[0]), re.compile(parts[1]), parts[2]))
    return rules


def skip_reasons(output):
    """The reasons a test's output gives for its skips."""
    lines = output.splitlines()
    reasons = [m.group(1) for m in (re.search(r"SKIPPED:\s*(.*)", l, re.IGNORECASE) for l in lines) if m]
    for i, line in enumerate(lines):
        if re.search(r": Skipped$", line) and i + 1 < len(lines):  # GTEST_SKIP() << reason
            reasons.append(lines[i + 1].strip())
    return reasons or ["(no reason given)"]


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    junit = Path(sys.argv[1])
    allowed = sys.argv[2] if len(sys.argv) == 3 else Path(__file__).with_name("allowed-skips.txt")
    rules = allowed_rules(allowed)
    if not junit.exists():
        sys.exit(f"{junit}: no CTest results (run ctest with --output-junit)")
    bad, accepted = [], []
    for case in ET.parse(junit).getroot().iter("testcase"):
        if case.get("status") == "run" and case.find("skipped") is None:
            continue
        if case.find("failure") is not None or case.get("status") == "fail":
            continue  # a failure fails CTest itself
        name = case.get("name")
        output = case.findtext("system-out") or ""
        reasons = ["disabled"] if case.get("status") == "disabled" else skip_reasons(output)
        for reason in reasons:
            rule = next((r for r in rules if r[0].fullmatch(name) and r[1].search(reason)), None)
            (accepted if rule else bad).append((name, reason, rule[2] if rule else ""))
    for name, reason, why in accepted:
        print(f"allowed skip: {name}: {reason} ({why})")
    for name, reason, _ in bad:
        print(f"SKIPPED WITHOUT LEAVE: {name}: {reason}")
    if bad:
        print(f"{len(bad)} skip(s) not in {allowed}: a skipped test is not a pass; fix the cause, or list it there "
              "with the reason it may skip")
        return 1
    print(f"skips: {len(accepted)}, all allowed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
