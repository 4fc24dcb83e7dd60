"""``modelDescription.xml`` of the FMU (FMI 2.0, model exchange and co-simulation).

The variables, in value-reference order (the runtime's ``VR_*``): the parameters (every
numeric field of the model's config sections, tunable where the FMU recomputes what follows
from it, else a constant with the design's value: :mod:`suspopt.fmu.params`), the inputs (the
road under each wheel and, where the tyre damps, its rate; none with an embedded road), the
outputs (every signal of the design's signal table, :mod:`suspopt.fmu.outputs`), and the
continuous states ``x.<dof>`` (displacements from static equilibrium), ``v.<dof>`` (their
derivatives, the velocities) and ``der(v.<dof>)`` (the accelerations). Units are FMI unit
definitions with SI base-unit exponents, parsed from suspopt's unit strings; the provenance
(suspopt's version, the config's SHA-256, the road's seed, the pick) is in the model's
``description`` and in a ``suspopt`` vendor annotation.
"""

from __future__ import annotations

import re
from datetime import UTC, datetime
from xml.sax.saxutils import quoteattr

from .description import Description
from .outputs import fmi_name
from .params import Bound

__all__ = ["model_description", "base_units"]

_BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")
#: Named units as exponents of the base units (and a factor, 1 for SI).
_NAMED = {
    "kg": {"kg": 1},
    "m": {"m": 1},
    "s": {"s": 1},
    "A": {"A": 1},
    "K": {"K": 1},
    "mol": {"mol": 1},
    "cd": {"cd": 1},
    "rad": {"rad": 1},
    "N": {"kg": 1, "m": 1, "s": -2},
    "J": {"kg": 1, "m": 2, "s": -2},
    "W": {"kg": 1, "m": 2, "s": -3},
    "Pa": {"kg": 1, "m": -1, "s": -2},
    "Hz": {"s": -1},
    "1": {},
    "-": {},
    "cycles": {},
}
_TOKEN = re.compile(r"\s*([A-Za-z]+|\d+(?:\.\d+)?|[()^*/-])")
#: Outputs that change only at the controller's samples or the lag's steps.
_DISCRETE_HEADS = ("damping", "damper_state", "control_condition", "control_threshold")


def _tokens(text: str) -> list[str]:
    out, at = [], 0
    text = text.strip()
    while at < len(text):
        m = _TOKEN.match(text, at)
        if m is None:
            raise ValueError(text)
        out.append(m.group(1))
        at = m.end()
    return out


def base_units(unit: str) -> dict[str, float] | None:
    """The SI base-unit exponents of the unit string ``unit`` (``N s/m``, ``(m/s^2)^2``,
    ``m^2/s^3``: juxtaposition multiplies, ``/`` divides by the next factor), or None when it
    is not one."""
    if unit in ("1", "-"):
        return {}
    try:
        tokens = _tokens(unit)
        exps, rest = _product(tokens)
    except (ValueError, IndexError, KeyError):
        return None
    return None if rest else exps


def _product(tokens: list[str]) -> tuple[dict[str, float], list[str]]:
    total: dict[str, float] = {}
    sign = 1.0
    while tokens and tokens[0] != ")":
        if tokens[0] in ("*", "/"):
            sign = -1.0 if tokens.pop(0) == "/" else 1.0
            continue
        factor, tokens = _factor(tokens)
        for k, v in factor.items():
            total[k] = total.get(k, 0.0) + sign * v
        sign = 1.0
    return total, tokens


def _factor(tokens: list[str]) -> tuple[dict[str, float], list[str]]:
    head = tokens.pop(0)
    if head == "(":
        inner, tokens = _product(tokens)
        if tokens.pop(0) != ")":
            raise ValueError(head)
    else:
        inner = dict(_NAMED[head])
    if tokens and tokens[0] == "^":
        tokens.pop(0)
        negative = tokens[0] == "-" and bool(tokens.pop(0))
        power = float(tokens.pop(0)) * (-1.0 if negative else 1.0)
        inner = {k: v * power for k, v in inner.items()}
    return inner, tokens


def _unit_definitions(units: set[str]) -> str:
    lines = ["  <UnitDefinitions>"]
    for unit in sorted(units):
        exps = base_units(unit)
        if exps is not None and all(float(v).is_integer() for v in exps.values()):
            attrs = "".join(f' {k}="{int(v)}"' for k, v in exps.items() if v and k in _BASE)
            lines.append(f"    <Unit name={quoteattr(unit)}><BaseUnit{attrs}/></Unit>")
        else:
            lines.append(f"    <Unit name={quoteattr(unit)}/>")
    lines.append("  </UnitDefinitions>")
    return "\n".join(lines)


def _variable(name, vr, description, causality, variability, real, initial=None) -> str:
    attrs = f'name={quoteattr(name)} valueReference="{vr}"'
    if description:
        attrs += f" description={quoteattr(description)}"
    attrs += f' causality="{causality}" variability="{variability}"'
    if initial:
        attrs += f' initial="{initial}"'
    return f"    <ScalarVariable {attrs}>\n      <Real{real}/>\n    </ScalarVariable>"


def _real(unit: str | None = None, start: float | None = None, derivative: int | None = None):
    out = ""
    if unit is not None:
        out += f" unit={quoteattr(unit)}"
    if start is not None:
        out += f' start="{float(start)!r}"'
    if derivative is not None:
        out += f' derivative="{derivative}"'
    return out


def _variables(d: Description, bound: Bound) -> tuple[list[str], dict[str, list[int]], set]:
    """The ScalarVariables and the 1-based indices of the outputs, states' derivatives and
    initial unknowns; the units used."""
    rows: list[str] = []
    units: set[str] = set()
    index: dict[str, list[int]] = {"outputs": [], "derivatives": [], "initial": []}

    def unit_of(u):
        if u and base_units(u) is not None:
            units.add(u)
            return u
        return None

    for p in bound.parameters:
        if p.tunable:
            real = _real(unit_of(p.unit), p.value)
            rows.append(
                _variable(
                    fmi_name(p.path),
                    len(rows),
                    p.description,
                    "parameter",
                    "tunable",
                    real,
                    "exact",
                )
            )
        else:
            text = f"{p.description} (a constant of this FMU: {p.reason})".lstrip()
            real = _real(unit_of(p.unit), p.value)
            rows.append(
                _variable(fmi_name(p.path), len(rows), text, "local", "constant", real, "exact")
            )
    for name, unit, text, _ in d.info["inputs"]:
        rows.append(
            _variable(name, len(rows), text, "input", "continuous", _real(unit_of(unit), 0.0))
        )
    for fmi, signal, unit, text in d.info["outputs"]:
        discrete = signal.split(".")[0] in _DISCRETE_HEADS
        rows.append(
            _variable(
                fmi,
                len(rows),
                f"{text} ({signal})",
                "output",
                "discrete" if discrete else "continuous",
                _real(unit_of(unit)),
            )
        )
        index["outputs"].append(len(rows))
    _states(d, rows, index, unit_of)
    return rows, index, units


def _states(d: Description, rows: list[str], index: dict, unit_of) -> None:
    """``x.<dof>``, ``v.<dof>`` = der(x) and ``der(v.<dof>)``."""
    dofs = d.info["dof_names"]
    unit = [("rad" if dof in ("body.roll", "body.pitch") else "m") for dof in dofs]
    first_x = len(rows) + 1
    for dof, u in zip(dofs, unit):
        rows.append(
            _variable(
                fmi_name(f"x.{dof}"),
                len(rows),
                f"{dof} from static equilibrium",
                "local",
                "continuous",
                _real(unit_of(u), 0.0),
                "exact",
            )
        )
    first_v = len(rows) + 1
    for i, (dof, u) in enumerate(zip(dofs, unit)):
        rows.append(
            _variable(
                fmi_name(f"v.{dof}"),
                len(rows),
                f"{dof} rate",
                "local",
                "continuous",
                _real(unit_of(u + "/s"), 0.0, first_x + i),
                "exact",
            )
        )
        index["derivatives"].append(len(rows))
    for i, (dof, u) in enumerate(zip(dofs, unit)):
        rows.append(
            _variable(
                f"der({fmi_name(f'v.{dof}')})",
                len(rows),
                f"{dof} acceleration (the equations of motion)",
                "local",
                "continuous",
                _real(unit_of(u + "/s^2"), None, first_v + i),
                "calculated",
            )
        )
        index["derivatives"].append(len(rows))
        index["initial"].append(len(rows))


def model_description(
    d: Description, bound: Bound, identifier: str, guid: str, provenance: dict[str, str]
) -> str:
    """The XML text (module docstring); ``provenance``: suspopt's version, the config's
    SHA-256, seed, pick, source, road mode, for the description and the vendor annotation."""
    rows, index, units = _variables(d, bound)
    sources = "".join(f'<File name="{f}"/>' for f in ("model.c", "runtime.c"))
    cs_inputs = 'canInterpolateInputs="true" ' if d.info["inputs"] else ""
    info = d.info
    text = (
        f"suspopt {provenance['version']} design {provenance['pick']} of "
        f"{provenance['source']}: {info['preset']} model, road {provenance['road']} "
        f"(config sha256 {provenance['config_sha256']}, seed {provenance['seed']})"
    )
    annotation = "".join(f" {k}={quoteattr(str(v))}" for k, v in provenance.items())
    structure = ["  <ModelStructure>", "    <Outputs>"]
    structure += [f'      <Unknown index="{i}"/>' for i in index["outputs"]]
    structure += ["    </Outputs>", "    <Derivatives>"]
    structure += [f'      <Unknown index="{i}"/>' for i in index["derivatives"]]
    structure += ["    </Derivatives>", "    <InitialUnknowns>"]
    structure += [f'      <Unknown index="{i}"/>' for i in index["outputs"] + index["initial"]]
    structure += ["    </InitialUnknowns>", "  </ModelStructure>"]
    now = datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
    return "\n".join(
        [
            '<?xml version="1.0" encoding="UTF-8"?>',
            f'<fmiModelDescription fmiVersion="2.0" modelName={quoteattr(identifier)} '
            f'guid="{guid}" description={quoteattr(text)} '
            f'generationTool="suspopt {provenance["version"]}" generationDateAndTime="{now}" '
            f'variableNamingConvention="structured" numberOfEventIndicators="0">',
            f'  <ModelExchange modelIdentifier="{identifier}" completedIntegratorStepNotNeeded='
            f'"true" canNotUseMemoryManagementFunctions="true"><SourceFiles>{sources}'
            "</SourceFiles></ModelExchange>",
            f'  <CoSimulation modelIdentifier="{identifier}" '
            f'canHandleVariableCommunicationStepSize="true" {cs_inputs}'
            f'canNotUseMemoryManagementFunctions="true"><SourceFiles>{sources}'
            "</SourceFiles></CoSimulation>",
            _unit_definitions(units),
            "  <LogCategories>",
            '    <Category name="logStatusError" description="errors: bad calls, divergence"/>',
            "  </LogCategories>",
            f'  <DefaultExperiment startTime="0.0" stopTime="{float(info["duration"])!r}" '
            f'stepSize="{float(info["output_dt"])!r}" tolerance="1e-08"/>',
            f'  <VendorAnnotations><Tool name="suspopt"><Export{annotation}/></Tool>'
            "</VendorAnnotations>",
            "  <ModelVariables>",
            *rows,
            "  </ModelVariables>",
            *structure,
            "</fmiModelDescription>",
            "",
        ]
    )
