"""The public API's docstrings (``suspopt.__all__``) in numpydoc form, as python-control's
docstring test checks its own: every parameter of a function documented under Parameters,
a Returns section where something is returned, every field of a result class under
Attributes, and every numeric entry with its unit."""

from __future__ import annotations

import dataclasses
import inspect
import re

import pytest
from numpydoc.docscrape import NumpyDocString

import suspopt

PUBLIC = [name for name in suspopt.__all__ if name != "__version__"]
#: A unit in brackets ([m], [N s/m], [-]), the words that say where it comes from, or an index.
UNIT = re.compile(r"\[[^\]]+\]|\bunits?\b|\bSI\b|\b[Ii]nd(?:ex|ices)\b")
NUMERIC = re.compile(r"float|array|ndarray|int\b")


def _entries(doc: NumpyDocString, section: str) -> dict:
    return {p.name.strip("*"): p for p in doc[section]}


def _check_units(entries: dict, where: str) -> list[str]:
    return [
        f"{where}: {name} ({e.type}) names no unit"
        for name, e in entries.items()
        if NUMERIC.search(e.type) and not UNIT.search(" ".join(e.desc))
    ]


@pytest.mark.parametrize("name", PUBLIC)
def test_public_docstrings_document_parameters_returns_and_units(name):
    obj = getattr(suspopt, name)
    assert obj.__doc__ and obj.__doc__.strip(), f"{name}: no docstring"
    if inspect.isclass(obj) and issubclass(obj, Exception):
        return
    if inspect.isclass(obj) and hasattr(obj, "model_fields"):  # the pydantic config
        undocumented = [f for f, info in obj.model_fields.items() if not info.description]
        assert not undocumented, f"{name}: fields without a description: {undocumented}"
        return
    doc = NumpyDocString(inspect.getdoc(obj))
    problems = []
    if inspect.isclass(obj) and dataclasses.is_dataclass(obj):
        attributes = _entries(doc, "Attributes")
        missing = [
            f.name
            for f in dataclasses.fields(obj)
            if not f.name.startswith("_") and f.name not in attributes
        ]
        problems += [f"{name}: attributes not documented: {missing}"] if missing else []
        problems += _check_units(attributes, name)
    else:
        target = obj.__init__ if inspect.isclass(obj) else obj
        signature = inspect.signature(target)
        wanted = [p for p in signature.parameters if p not in ("self", "cls")]
        parameters = _entries(doc, "Parameters")
        missing = [p for p in wanted if p not in parameters]
        problems += [f"{name}: parameters not documented: {missing}"] if missing else []
        problems += _check_units(parameters, name)
        returns = signature.return_annotation
        if not inspect.isclass(obj) and returns not in (None, "None", inspect.Signature.empty):
            problems += [] if doc["Returns"] else [f"{name}: no Returns section"]
    assert not problems, problems
