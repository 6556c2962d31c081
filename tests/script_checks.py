"""The checks of the project's Python test scripts (run_bag_test.py, trim_timing_test.py): each
printed as it is made, "ok" or "FAIL", and the script's exit code from them (ctest reads it)."""
import sys

_failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what)
    if not condition:
        _failures.append(what)


def finish():
    """Exits 1 if any check failed, else 0."""
    sys.exit(1 if _failures else 0)
