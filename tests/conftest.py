"""Test-suite set-up: the shared helpers beside this file (sphere_reference.py) import by name
from any test folder (tests run with --import-mode=importlib, which adds no folder to sys.path)."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

import os

import pytest

# CI sets this (.ci/run): a test that skips because ../shared data are missing fails instead,
# so a clone without the data cannot pass by skipping (skip reasons say "... data not found")
REQUIRE_SHARED = os.environ.get("MBCONTROL_REQUIRE_SHARED") == "1"


def _skipped_for_missing_data(report) -> bool:
    reason = report.longrepr[-1] if isinstance(report.longrepr, tuple) else str(report.longrepr)
    return report.skipped and "data not found" in str(reason)


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    outcome = yield
    report = outcome.get_result()
    if REQUIRE_SHARED and _skipped_for_missing_data(report):
        report.outcome = "failed"


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    if REQUIRE_SHARED and _skipped_for_missing_data(report):
        report.outcome = "failed"


# Parallel runs (make test: pytest-xdist, --dist loadfile). A file is one unit of work, so its
# module-scoped fixtures (a plant, a benchmark table) are built once, on one worker: split by
# test, the WECCCOMP table (60 s) was built three times. (--dist loadgroup would let each
# notebook be a unit, but xdist 3.8 marks its groups in a node attribute pytest 9 no longer
# reads.) Files start longest first (these, measured on a cold cache on a 2-core machine; the
# order only balances the workers, it changes no result), the rest in collection order.
LONGEST_FIRST = (
    "tests/test_notebooks.py", "tests/test_readme.py", "tests/studies/sweep/test_sweep.py",
    "tests/test_cli.py", "tests/controllers/test_nmpc.py", "tests/controllers/test_joint.py",
    "tests/studies/identify/test_identify.py", "tests/controllers/test_electrical.py",
    "tests/studies/identify/test_flume_data.py", "tests/hydro/test_bem.py",
    "tests/controllers/test_wecccomp.py", "tests/hydro/test_fit_where_it_matters.py",
    "tests/export/test_export.py", "tests/hydro/test_fixed_bodies.py",
    "tests/cli/test_identify.py", "tests/hydro/test_radiation.py",
)


def pytest_collection_modifyitems(config, items):
    rank = {unit: i for i, unit in enumerate(LONGEST_FIRST)}
    position = {id(item): i for i, item in enumerate(items)}
    items.sort(key=lambda item: (rank.get(item.nodeid.split("::")[0], len(rank)),
                                 position[id(item)]))
