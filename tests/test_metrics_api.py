"""Package-wide contracts of suspopt.metrics: exports, no Python loop over designs, batching."""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil

import numpy as np
import pytest

import suspopt.metrics as metrics

MODULES = [
    importlib.import_module(f"suspopt.metrics.{info.name}")
    for info in pkgutil.iter_modules(metrics.__path__)
]
LOOPS = (
    ast.For,
    ast.While,
    ast.AsyncFor,
    ast.ListComp,
    ast.SetComp,
    ast.DictComp,
    ast.GeneratorExp,
)


def test_every_module_declares_all_and_the_package_reexports_it():
    assert {module.__name__.rsplit(".", 1)[1] for module in MODULES} == {
        "iso2631",
        "stats",
        "energy",
        "transient",
        "spectral",
        "springs",
    }
    for module in MODULES:
        for name in module.__all__:
            assert hasattr(module, name), (module.__name__, name)
            if inspect.isfunction(getattr(module, name)):
                assert getattr(metrics, name) is getattr(module, name), name


@pytest.mark.parametrize("module", MODULES, ids=lambda m: m.__name__)
def test_no_python_loop_inside_any_function(module):
    """Batching is numpy's job: a loop in a metric would run per design (or per sample)."""
    tree = ast.parse(inspect.getsource(module))
    functions = [
        node for node in ast.walk(tree) if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
    ]
    loops = [
        f"{function.name}:{node.lineno}"
        for function in functions
        for node in ast.walk(function)
        if isinstance(node, LOOPS)
    ]
    assert not loops, f"loops in {module.__name__}: {loops}"


BATCH = np.random.default_rng(3).standard_normal((4, 1500))
ROW_FUNCTIONS = {
    "weighted_rms": lambda a: metrics.weighted_rms(a, 500.0, "Wk"),
    "mtvv": lambda a: metrics.mtvv(a, 500.0, "Wd"),
    "vdv": lambda a: metrics.vdv(a, 500.0, "Wf"),
    "crest_factor": lambda a: metrics.crest_factor(a, 500.0, "We"),
    "var": metrics.var,
    "peak_to_peak": metrics.peak_to_peak,
    "DE": lambda a: metrics.mean_dissipated_power_from_damping(1500.0, a, np.arange(1500) / 500),
    "SW": lambda a: metrics.damper_switches(np.sign(a), tol=0.5),
    "usage": lambda a: metrics.nonlinear_spring_usage(0.01 * a, 5e4, 1e7),
}


@pytest.mark.parametrize("name", ROW_FUNCTIONS)
def test_batch_of_designs_equals_single_calls(name):
    function = ROW_FUNCTIONS[name]
    batched = function(BATCH)
    assert batched.shape == (4,)
    np.testing.assert_allclose(batched, [function(row) for row in BATCH], rtol=1e-12)
