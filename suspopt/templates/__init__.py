"""Starter configs for ``suspopt init KIND -o case.yaml``: one commented YAML file per kind.

Each template is a real config in SI units that validates and runs as it is: its comments say
what every key means and which thesis table or equation its numbers come from, and its run is
short (a comment says how to make it longer). The files sit beside this module as
``<kind>.yaml``; to add a template, add the file and its one-line description to
:data:`!TEMPLATES` (tests/test_templates.py checks, validates and runs every entry).
"""

from __future__ import annotations

from importlib import resources

from ..errors import check_known

__all__ = [
    "TEMPLATES",
    "template_names",
    "template_description",
    "template_text",
    "load_template",
]

#: Template kinds in the order ``suspopt init --help`` lists them, with one line each.
TEMPLATES: dict[str, str] = {
    "quarter": "quarter car of Table 3.1 on an ISO 8608 class B road (ride comfort)",
    "half_roll": "half car in roll of Table 3.1, a step under the right wheels (roll)",
    "half_pitch": "half car in pitch of Table 5.1, Duffing springs, half-sine bump (pitch)",
    "full": "full car of Table 3.1 on class B with independent left and right tracks",
    "seat": "Ch. 8 quarter car with a passive seat and the Table 2.3 passenger, class A",
    "semi_active": "Ch. 4 quarter car, SH-2 dampers, adaptive CDF threshold (control "
    "section), class C",
    "optimise": "GA on the Ch. 5 half car (Case 1: comfort under Eq 5.2-5.3), small budget",
    "kesort": "NSGA-II front of Ch. 6 Part B with supplementary objectives, for suspopt kesort",
    "spectral": "NSGA-II of the Ch. 8 PS seat on class A by the stationary spectral method",
    "robust": "the Ch. 8 PS seat in the worst of classes A-C x 75/95/115 kg (scenarios)",
}


def template_names() -> list[str]:
    """The template kinds, in the order of :data:`!TEMPLATES`."""
    return list(TEMPLATES)


def template_description(kind: str) -> str:
    """The one-line description of template ``kind`` (ValueError for an unknown kind)."""
    return TEMPLATES[check_known("template", kind, TEMPLATES)]


def template_text(kind: str) -> str:
    """The YAML text of template ``kind``, comments included; ValueError naming the closest
    kinds for an unknown one."""
    check_known("template", kind, TEMPLATES)
    return resources.files(__name__).joinpath(f"{kind}.yaml").read_text(encoding="utf-8")


def load_template(kind: str):
    """The starter config of ``kind`` (``suspopt init KIND``) loaded, as
    :func:`suspopt.load_config` loads a file: what a script or a notebook starts from without
    writing the YAML out first.

    Parameters
    ----------
    kind : str
        One of :data:`!TEMPLATES` (``quarter``, ``half_pitch``, ``kesort``, ...).

    Returns
    -------
    Config
        The validated config, quantities in SI units.

    Raises
    ------
    ValueError
        For an unknown kind, naming the closest kinds.
    """
    from pathlib import Path

    from ..config.loader import load_config_text

    return load_config_text(template_text(kind), Path(f"{kind}.yaml"))
