"""Test-suite set-up. The shared helpers live in tests/helpers/ (a package) and are imported as
`tests.helpers.<name>`: tests run with --import-mode=importlib, which names each module by its path
from the rootdir, so `tests` resolves without any folder on sys.path (no test touches sys.path)."""
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
    "tests/features/test_notebooks.py", "tests/features/test_readme.py",
    "tests/features/studies/sweep/test_sweep.py", "tests/features/test_cli.py",
    "tests/controllers/test_nmpc.py", "tests/controllers/test_joint.py",
    "tests/features/studies/identify/test_identify.py",
    "tests/features/controllers/test_electrical.py",
    "tests/features/studies/identify/test_flume_data.py", "tests/hydro/test_bem.py",
    "tests/features/controllers/test_wecccomp.py",
    "tests/features/hydro/test_fit_where_it_matters.py", "tests/features/export/test_export.py",
    "tests/features/hydro/test_fixed_bodies.py", "tests/cli/test_identify.py",
    "tests/hydro/fit/test_radiation.py",
)


def pytest_collection_modifyitems(config, items):
    rank = {unit: i for i, unit in enumerate(LONGEST_FIRST)}
    position = {id(item): i for i, item in enumerate(items)}
    items.sort(key=lambda item: (rank.get(item.nodeid.split("::")[0], len(rank)),
                                 position[id(item)]))
