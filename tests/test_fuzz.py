"""Fuzzing ``suspopt validate`` and ``suspopt simulate`` with broken configs.

Every bundled config (with a 0.3 s run and a tiny optimiser budget: the seeds of
:mod:`fuzz_harness`) is mutated: keys deleted, wrong types, non-finite and extreme numbers,
absurd sizes (duration, dt, n_waves, n_max, population ...), enum and key typos, YAML breakage,
alias bombs, self-referencing anchors, merge keys, deep nesting, duplicate keys, non-UTF-8
bytes; and the config path is also a directory, a FIFO, a symlink to /dev/zero, a symlink
loop. Each case runs ``validate CONFIG`` and ``simulate CONFIG -o OUT.h5`` in-process
(CliRunner) inside a worker process capped at 2 GB of address space, with a 3 s SIGALRM per
command. Each must exit 0, or exit 2 with one line on stderr that names the file and no
traceback; whatever ``validate`` accepts, ``simulate`` must write.

The seed is fixed (:data:`fuzz_harness.SEED`); ``SUSPOPT_FUZZ_CASES`` (env) sets the number of
random mutations (default 500); ``SUSPOPT_FUZZ_WORKERS`` the worker processes (default 2).
Long runs with a summary table: ``python benchmarks/fuzz_configs.py --cases 2000``.
"""

from __future__ import annotations

import fuzz_harness as fh
import pytest

pytestmark = pytest.mark.slow

DEFAULT_CASES = 500
CASES = fh.config_cases(fh.case_count(DEFAULT_CASES))


@pytest.fixture(scope="module")
def results(request):
    """Run the selected cases (all of them unless -k deselects some) in one worker pool."""
    wanted = fh.selected_case_ids(request)
    return fh.run_cases([c for c in CASES if c.id in wanted])


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_config_case(case, results):
    result = results[case.id]
    found = fh.problems(case, result)
    assert not found, fh.describe(case, result, found)
