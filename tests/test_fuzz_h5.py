"""Fuzzing the commands that read Pareto files with broken ones.

A real tiny front (``ch8/pareto_ps_class_a`` optimised for 0.3 s runs, population 10, two
generations: ``conftest.optimised_front``) is made once, then broken: truncated, random bytes,
empty, a directory, a FIFO, a symlink to /dev/zero; no ``/pareto``; each of ``/pareto/X``,
``F``, ``G`` deleted or replaced by text, by the wrong shape (1-D, 3-D, zero rows), by
NaN/inf, by a chunked dataset of 10^12 rows with nothing written; ``names``/``units``
attributes missing or of the wrong length; names that do not match the stored config; the root
``config`` attribute missing, not UTF-8, a YAML error, an alias bomb, another config;
``/baseline`` (the config's own design) as text, 3-D, without names or G, NaN, a dataset; plus
seeded random byte flips (``SUSPOPT_FUZZ_H5_CASES``, default 48). ``kesort``, ``analyse
roads --road B``, ``analyse masses`` and ``analyse transmissibility`` run on each, in-process
in a worker capped at 2 GB with a 3 s SIGALRM per command (:mod:`fuzz_harness`). Each must
exit 0, or exit 2 with one line that names the file, and the dataset (or ``config``) at fault.
"""

from __future__ import annotations

import os

import fuzz_harness as fh
import pytest

pytestmark = pytest.mark.slow

VARIANTS = fh.h5_variants() + fh.h5_random_variants(
    int(os.environ.get("SUSPOPT_FUZZ_H5_CASES", "48"))
)
CASES = fh.h5_cases(VARIANTS)


@pytest.fixture(scope="module")
def results(request, tmp_path_factory):
    wanted = fh.selected_case_ids(request)
    cases = fh.build_h5_cases(
        [c for c in CASES if c.id in wanted], VARIANTS, tmp_path_factory.mktemp("fuzz_h5")
    )
    return fh.run_cases(cases)


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_pareto_case(case, results):
    result = results[case.id]
    found = fh.problems(case, result)
    assert not found, fh.describe(case, result, found)
