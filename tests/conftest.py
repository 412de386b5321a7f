import atexit
import os
import sys


def _silence_nanobind_leak_report() -> None:
    # OMPL objects alive at exit (e.g. in tracebacks kept by pytest) make nanobind print a leak
    # report after the results; harmless (STACK.md §1.13).
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(os.open(os.devnull, os.O_WRONLY), 2)


atexit.register(_silence_nanobind_leak_report)
