"""``suspopt analyse KIND --help``: each analysis kind's own help - what it does, the options
it takes and an example command line - while ``suspopt analyse KIND SOURCE ...`` stays one
command (see :mod:`suspopt.cli.analysis`)."""

from __future__ import annotations

import copy
from typing import Any

from typer.core import TyperCommand

#: An example command line of each kind (from docs/guide/analyses.md).
EXAMPLES = {
    "models": "suspopt analyse models qc.yaml hc1.yaml fc.yaml --reference qc.yaml "
    "-o models.h5 --plot models.png",
    "roads": "suspopt analyse roads ps.h5 --road B --road configs/ch8/ps_class_c.yaml "
    "-o ps_roads.h5 --plot ps_roads.png",
    "masses": "suspopt analyse masses ps.h5 --mass-change -20 --mass-change 20 "
    "-o ps_masses.h5 --plot ps_masses.png",
    "controllers": "suspopt analyse controllers sh_2.h5 --with configs/ch7/sh_2_cdf.yaml "
    "-o sh_2_cdf.h5",
    "transmissibility": "suspopt analyse transmissibility ps.h5 "
    "--with configs/ch8/ps_class_a_passenger.yaml -o ps_stht.h5 --plot ps_stht.png",
    "scenarios": "suspopt analyse scenarios robust.h5 -o spread.h5 --plot spread.png",
    "tolerances": "suspopt analyse tolerances front.h5 --tolerance 10 --tolerance K_lF1=5 "
    "-o built.h5 --plot built.png",
    "builds": "suspopt analyse builds front.h5 --samples 200 --seed 1 -o builds.h5 "
    "--plot builds.png",
    "cdf-sensitivity": "suspopt analyse cdf-sensitivity sa.yaml -o cdf.h5 --plot cdf.png",
}
#: The parameters every kind takes (the others are named by the kind's options).
_EVERY_KIND = {
    "kind",
    "sources",
    "output",
    "plot",
    "full",
    "force",
    "max_memory",
    "executor",
    "scheduler",
    "workers",
}
_KEY = "suspopt.analyse.kind"


def _kind_asked(args: list[str]) -> str | None:
    """The kind of ``analyse KIND ... --help``: the first argument, when ``--help`` is
    given and it names a kind."""
    from ..analyse import SUMMARIES

    if "--help" not in args or not args or args[0] not in SUMMARIES:
        return None
    return args[0]


def kind_help(kind: str) -> str:
    """The help text of ``analyse KIND``: what the kind does and an example."""
    from ..analyse import SUMMARIES

    return (
        f"analyse {kind}: {SUMMARIES[kind]}.\n\n"
        f"Example:\n\n{EXAMPLES[kind]}\n\n"
        "See docs/guide/analyses.md for what its table and files hold."
    )


class AnalyseCommand(TyperCommand):
    """The ``analyse`` command, whose ``--help`` after a kind shows that kind's help: its
    description and example (:func:`kind_help`), its usage and only the options it takes."""

    def parse_args(self, ctx: Any, args: list[str]) -> list[str]:
        kind = _kind_asked(args)
        if kind is not None:  # (--help is eager: it is shown while these are parsed)
            ctx.meta[_KEY] = kind
        return super().parse_args(ctx, args)

    def format_help(self, ctx: Any, formatter: Any) -> None:
        kind = ctx.meta.get(_KEY)
        if kind is None:
            return super().format_help(ctx, formatter)
        from ..analyse import analysis_kinds

        spec = analysis_kinds()[kind]
        taken = _EVERY_KIND | set(spec.options)
        view = copy.copy(self)
        view.help = kind_help(kind).replace("[", "\\[")
        view.params = [p for p in self.params if p.name in taken and p.name != "kind"]
        sources = "SOURCE..." if spec.many else "SOURCE"
        usage = f"{kind} {sources} [OPTIONS]"
        view.options_metavar = usage
        view.collect_usage_pieces = lambda ctx: [usage]  # type: ignore[method-assign]
        return TyperCommand.format_help(view, ctx, formatter)
