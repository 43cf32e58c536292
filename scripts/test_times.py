#!/usr/bin/env python3
"""How long each CTest test of a run took against its timeout.

    scripts/test_times.py BUILD_DIR JUNIT_XML [--top N] [--strict]

Reads the run's JUnit file (`ctest --output-junit`) and the tests' timeouts
(`ctest --show-only=json-v1`), and prints the run's total, its slowest tests
with their share of their timeout, and every test that took more than half of
its timeout: a test that close to its limit fails on a slower machine, so its
timeout (meshseek_add_test's TIMEOUT or CASE_TIMEOUTS) or its data should
change. --strict exits 1 when there is one. scripts/test.sh and
scripts/sanitize.sh call it after every ctest run (docs/operations.md,
"Continuous integration").
"""
import argparse
import json
import subprocess
import sys
import xml.etree.ElementTree as ET


def timeouts(build_dir):
    listed = subprocess.run(
        ["ctest", "--test-dir", build_dir, "--show-only=json-v1"],
        check=True, capture_output=True, text=True).stdout
    out = {}
    for test in json.loads(listed)["tests"]:
        for prop in test.get("properties", []):
            if prop["name"] == "TIMEOUT":
                out[test["name"]] = float(prop["value"])
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build_dir")
    parser.add_argument("junit")
    parser.add_argument("--top", type=int, default=12)
    parser.add_argument("--strict", action="store_true")
    args = parser.parse_args()

    limit = timeouts(args.build_dir)
    # CTest's default when a test sets none (DART_TESTING_TIMEOUT).
    default = 1500.0
    rows = []
    for case in ET.parse(args.junit).getroot().iter("testcase"):
        name = case.get("name")
        seconds = float(case.get("time", 0))
        rows.append((seconds, name, limit.get(name, default), case.get("status", "")))
    rows.sort(reverse=True)
    total = sum(r[0] for r in rows)
    print(f"test_times: {len(rows)} tests, {total:.0f} s of test time; slowest:")
    for seconds, name, timeout, status in rows[:args.top]:
        print(f"  {seconds:7.1f} s  {100 * seconds / timeout:3.0f} % of {timeout:5.0f} s  {name}"
              + ("" if status in ("run", "") else f"  ({status})"))
    over = [r for r in rows if r[0] > r[2] / 2]
    for seconds, name, timeout, _ in over:
        print(f"test_times: WARNING {name} took {seconds:.1f} s, more than half of its "
              f"{timeout:.0f} s timeout")
    return 1 if (over and args.strict) else 0


if __name__ == "__main__":
    sys.exit(main())
