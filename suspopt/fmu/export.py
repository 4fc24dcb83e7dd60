"""``suspopt export SOURCE --fmu design.fmu``: one design as an FMI 2.0 FMU (:func:`export_fmu`),
or the picks of a result file, one FMU each (:func:`export_picks`).

The FMU is a zip file: ``modelDescription.xml`` (first, stored, so that suspopt knows its own
FMU by the marker in its first bytes, :func:`suspopt.io.is_suspopt_output`), ``sources/`` (the
generated ``model.c``/``model.h``, the runtime and the FMI headers), ``binaries/<platform>/``
(the shared library, when a C compiler is found: :mod:`suspopt.fmu.build`) and
``resources/config.yaml`` (the design's config, the FMU's provenance in full). It is written
atomically (:func:`suspopt.io.atomic_file`): a failed export leaves nothing behind.
"""

from __future__ import annotations

import hashlib
import re
import uuid
import zipfile
from dataclasses import dataclass
from pathlib import Path

from .._version import __version__
from ..config import Config, ConfigError
from .build import compile_binary
from .csource import COMPILED, sources
from .model import describe
from .modeldescription import model_description
from .params import bind_parameters

__all__ = ["export_fmu", "export_picks", "Exported", "pick_path"]


@dataclass
class Exported:
    """What :func:`export_fmu` wrote: the ``path``, the ``identifier`` (the binary's name),
    the ``binary`` inside it (None: source-only) and ``note`` (the compiler, or why none ran),
    the tunable and constant parameters, the inputs and outputs."""

    path: Path
    identifier: str
    binary: str | None
    note: str
    tunable: int
    constants: int
    inputs: int
    outputs: int


def identifier_of(path: Path) -> str:
    """The FMU's model identifier (a C identifier) from its file name."""
    name = re.sub(r"[^A-Za-z0-9_]", "_", Path(path).stem) or "design"
    return name if name[0].isalpha() else "fmu_" + name


def pick_path(path: Path, pick: str) -> Path:
    """The FMU of ``pick`` when one ``--fmu`` names several: ``design-chosen.fmu``."""
    path = Path(path)
    safe = re.sub(r"[^A-Za-z0-9_.+-]", "_", pick)
    return path.with_name(f"{path.stem}-{safe}{path.suffix}")


def _provenance(cfg: Config, pick: str, source: str, road: str, design_id: str) -> dict:
    seed = getattr(cfg.road, "seed", None)
    return {
        "version": __version__,
        "config_sha256": hashlib.sha256(cfg.text.encode()).hexdigest(),
        "seed": -1 if seed is None else int(seed),
        "pick": pick,
        "design_id": design_id,
        "source": source,
        "road": road,
    }


def export_fmu(
    cfg: Config,
    path: str | Path,
    road: str = "input",
    pick: str = "config",
    source: str | None = None,
    design_id: str = "",
    force: bool = False,
) -> Exported:
    """Write the design of ``cfg`` (its config values) as an FMU at ``path``.

    Parameters
    ----------
    cfg : Config
        The design's config (:func:`suspopt.choosing.picks.design_config` of a pick, or a config).
    path : str or Path
        The FMU to write (``.fmu``), replaced only if suspopt wrote it, or with ``force``.
    road : str
        ``input`` (the road under each wheel from the FMU's inputs) or ``embedded`` (the
        config's road built in: the FMU alone reproduces ``suspopt simulate``).
    pick, source, design_id : str
        What the FMU records of where the design came from.

    Returns
    -------
    Exported
        ConfigError (nothing written) for a model or target the FMU cannot take.
    """
    from ..io import atomic_file

    path = Path(path)
    d = describe(cfg, road)
    bound = bind_parameters(cfg, road, d)
    identifier = identifier_of(path)
    provenance = _provenance(cfg, pick, source or str(cfg.source or "the config"), road, design_id)
    draft = model_description(d, bound, identifier, "{GUID}", provenance)
    files = sources(d, bound, "{GUID}")
    digest = hashlib.sha256(draft.encode() + b"".join(files.values())).hexdigest()
    guid = "{" + str(uuid.UUID(digest[:32])) + "}"
    description = draft.replace('guid="{GUID}"', f'guid="{guid}"')
    files["model.h"] = files["model.h"].replace(b'"{GUID}"', f'"{guid}"'.encode())
    binary, note = compile_binary(files, COMPILED, identifier)
    with atomic_file(path, force) as stream, zipfile.ZipFile(stream, "w") as fmu:
        fmu.writestr("modelDescription.xml", description, zipfile.ZIP_STORED)
        for name, data in files.items():
            fmu.writestr(f"sources/{name}", data, zipfile.ZIP_DEFLATED)
        if binary is not None:
            fmu.writestr(binary[0], binary[1], zipfile.ZIP_DEFLATED)
        fmu.writestr("resources/config.yaml", cfg.text, zipfile.ZIP_DEFLATED)
    tunable = sum(p.tunable for p in bound.parameters)
    return Exported(
        path=path,
        identifier=identifier,
        binary=None if binary is None else binary[0],
        note=note,
        tunable=tunable,
        constants=len(bound.parameters) - tunable,
        inputs=len(d.info["inputs"]),
        outputs=len(d.info["outputs"]),
    )


def export_picks(
    source: str | Path, picks: list[str], path: str | Path, road: str = "input", force=False
) -> list[Exported]:
    """The designs ``picks`` of the result file ``source``, one FMU each: ``path`` for one
    pick, ``<stem>-<pick>.fmu`` beside it for several (:func:`pick_path`)."""
    from ..choosing.picks import design_config, read_picks

    picked = read_picks(source, picks)
    several = len(picked.names) > 1
    written = []
    for i, name in enumerate(picked.names):
        cfg, _ = design_config(picked, i)
        target = pick_path(Path(path), name) if several else Path(path)
        written.append(
            export_fmu(cfg, target, road, name, str(source), str(picked.ids[i]), force=force)
        )
    return written


def check_pick_targets(path: Path, picks: list[str]) -> list[Path]:
    """The FMUs ``export --fmu path --pick ...`` writes (one, or one per pick)."""
    if len(picks) <= 1:
        return [Path(path)]
    targets = [pick_path(Path(path), p) for p in picks]
    if len(set(targets)) != len(targets):
        raise ConfigError(f"--pick: {', '.join(picks)} name the same FMU twice")
    return targets
