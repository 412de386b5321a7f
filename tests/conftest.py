import atexit
import os
import sys

import pytest
from hypothesis import HealthCheck, settings


def _silence_nanobind_leak_report() -> None:
    # OMPL objects alive at exit (e.g. in tracebacks kept by pytest) make nanobind print a leak
    # report after the results; harmless (docs/stack.md, "Leak report at exit").
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(os.open(os.devnull, os.O_WRONLY), 2)


atexit.register(_silence_nanobind_leak_report)


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: took 0.3 s or more here (tests/slow_tests.txt); "
                                       "-m 'not slow' is the quick subset")


def pytest_collection_modifyitems(config, items):
    from slow_tests import marked  # tests/ is on the path: conftest.py's folder

    slow = marked()
    for item in items:
        if item.nodeid in slow:
            item.add_marker(pytest.mark.slow)


@pytest.fixture(scope="session", autouse=True)
def region_cache(request, tmp_path_factory):
    """Exact regions are cached on disk (planner.actions.region_cache): keep the tests' copy in pytest's cache
    folder, not the user's, for this process's default cache (made from the environment on first
    use, after this) and the ``plan`` commands it starts."""
    cache = getattr(request.config, "cache", None)  # None with -p no:cacheprovider
    folder = cache.mkdir("stablepush-regions") if cache else tmp_path_factory.mktemp("stablepush-regions")
    old = os.environ.get("STABLEPUSH_CACHE")
    os.environ["STABLEPUSH_CACHE"] = str(folder)
    yield folder
    if old is None:
        os.environ.pop("STABLEPUSH_CACHE")
    else:
        os.environ["STABLEPUSH_CACHE"] = old


# Hypothesis (tests/planner/model/test_fuzz_scenes.py): CI runs a fixed, derandomised budget that
# keeps the fuzz tests within about half a minute on two cores; `--hypothesis-profile long` runs 10,000 examples a
# test with fresh randomness (its example database, in .hypothesis/, which Hypothesis git-ignores
# itself, replays a failure first on the next run). Examples touch files, so no deadline.
_FUZZ = dict(deadline=None, print_blob=True, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
settings.register_profile("ci", max_examples=800, derandomize=True, **_FUZZ)
settings.register_profile("long", max_examples=10_000, **_FUZZ)
settings.load_profile("ci")  # the plugin's --hypothesis-profile, read later, overrides it
