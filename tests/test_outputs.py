"""Outputs: nothing overwritten unasked (a result of another config or options needs
``--force`` or ``--resume``, the old file unchanged byte for byte), output suffixes that name
their format, a result's figure replaced with it, long tables summarised on the terminal
(``--full`` for all) and each ``analyse`` kind's own help (:mod:`suspopt.replacing`,
:mod:`suspopt.cli.summary`, :mod:`suspopt.cli.kinds`)."""

from __future__ import annotations

import re
import sys

import h5py
import pytest
from conftest import CONFIGS, tiny

from suspopt._entry import main
from suspopt.analyse import SUMMARIES

pytestmark = pytest.mark.cli


def cli(capsys, *args) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("error: "), err
    return lines[0]


@pytest.fixture
def study(tmp_path, monkeypatch):
    """A tiny Ch. 8 PS seat study (2 generations of 10 designs) in a fresh folder."""
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "study.yaml"
    text = (CONFIGS / "ch8/pareto_ps_class_a.yaml").read_text()
    path.write_text(tiny(text, 1.5, population=10, generations=2))
    return path


@pytest.fixture(scope="module")
def front(tmp_path_factory):
    """A tiny PS front written by ``suspopt optimise`` (for the analyses)."""
    folder = tmp_path_factory.mktemp("front")
    path = folder / "study.yaml"
    text = (CONFIGS / "ch8/pareto_ps_class_a.yaml").read_text()
    path.write_text(tiny(text, 1.5, population=10, generations=2))
    out = folder / "front.h5"
    assert main(["-q", "optimise", str(path), "-o", str(out)]) == 0
    return out


@pytest.mark.slow
def test_optimise_onto_a_front_of_another_budget_is_refused_and_leaves_both_files(study, capsys):
    code, _, err = cli(capsys, "optimise", study, "-o", "front.h5", "--plot", "front.png")
    assert code == 0, err
    before = {name: (study.parent / name).read_bytes() for name in ("front.h5", "front.png")}
    code, _, err = cli(
        capsys, "optimise", study, "-o", "front.h5", "--set", "optimiser.generations=3"
    )
    assert code == 2
    line = _error_line(err)
    assert "front.h5 holds a front of another config (optimiser.generations 2, not 3)" in line
    assert "--force" in line and "--resume" in line
    after = {name: (study.parent / name).read_bytes() for name in before}
    assert after == before
    # another request onto it: another command's result, named so
    code, _, err = cli(capsys, "simulate", study, "-o", "front.h5")
    assert code == 2
    assert "holds a front of another command (suspopt optimise, not simulate)" in _error_line(err)
    assert (study.parent / "front.h5").read_bytes() == before["front.h5"]


@pytest.mark.slow
def test_force_replaces_a_front_and_removes_the_figure_of_the_old_one(study, capsys):
    folder = study.parent
    assert cli(capsys, "optimise", study, "-o", "front.h5", "--plot", "front.png")[0] == 0
    code, _, err = cli(
        capsys, "optimise", study, "-o", "front.h5", "--set", "optimiser.generations=3", "--force"
    )
    assert code == 0, err
    with h5py.File(folder / "front.h5") as h5:
        assert len(h5["history/generation"]) == 3
        assert "plot" not in h5.attrs
    assert not (folder / "front.png").exists()  # (of the old front: removed with it)


@pytest.mark.slow
def test_the_same_command_again_replaces_its_result_and_keeps_its_figure(study, capsys):
    folder = study.parent
    assert cli(capsys, "optimise", study, "-o", "front.h5", "--plot", "front.png")[0] == 0
    code, _, err = cli(capsys, "optimise", study, "-o", "front.h5")
    assert code == 0, err
    with h5py.File(folder / "front.h5") as h5:
        assert h5.attrs["plot"] == "front.png"
    assert (folder / "front.png").exists()


@pytest.mark.slow
def test_resume_rewrites_the_figure_of_the_run_it_continues(study, capsys):
    folder = study.parent
    assert cli(capsys, "optimise", study, "-o", "front.h5", "--plot", "front.png")[0] == 0
    old = (folder / "front.png").read_bytes()
    code, out, err = cli(
        capsys, "optimise", study, "-o", "front.h5", "--set", "optimiser.generations=4", "--resume"
    )
    assert code == 0, err
    assert "wrote front.png" in out
    assert (folder / "front.png").read_bytes() != old
    with h5py.File(folder / "front.h5") as h5:
        assert len(h5["history/generation"]) == 4 and h5.attrs["plot"] == "front.png"


@pytest.mark.parametrize(
    "args, needle",
    [
        (
            ("optimise", "{study}", "-o", "out.csv"),
            "-o out.csv: ends in .csv, but this writes HDF5",
        ),
        (("simulate", "{study}", "-o", "signals"), "-o signals: has no suffix"),
        (("init", "kesort", "-o", "study.json"), "-o study.json: ends in .json"),
        (("report", "{study}", "-o", "page.h5"), "-o page.h5: ends in .h5, but this writes HTML"),
    ],
)
def test_an_output_suffix_that_is_not_its_format_is_refused(study, capsys, args, needle):
    args = [a.format(study=study) for a in args]
    code, _, err = cli(capsys, *args)
    assert code == 2
    assert needle in _error_line(err)
    assert sorted(p.name for p in study.parent.iterdir()) == ["study.yaml"]


@pytest.mark.slow
def test_analyse_onto_its_result_of_other_options_is_refused(front, tmp_path, capsys):
    out = tmp_path / "tol.h5"
    args = ("analyse", "tolerances", front, "-o", out)
    assert cli(capsys, *args, "--tolerance", "10")[0] == 0
    before = out.read_bytes()
    code, _, err = cli(capsys, *args, "--tolerance", "5")
    assert code == 2
    line = _error_line(err)
    assert f"{out} holds an analysis of other options (--tolerance 10, not 5)" in line
    assert "--resume" not in line and out.read_bytes() == before
    assert cli(capsys, *args, "--tolerance", "10")[0] == 0  # (the same: replaced)
    assert cli(capsys, *args, "--tolerance", "5", "--force")[0] == 0


def test_a_figure_lands_with_its_result_or_neither_does(tmp_path):
    """Held together (:func:`suspopt.replacing.together`): a failure after both were written
    leaves both old files; the end of the block renames both."""
    from contextlib import ExitStack

    from suspopt import io
    from suspopt.replacing import together

    result, figure = tmp_path / "r.txt", tmp_path / "f.txt"
    for path in (result, figure):
        path.write_text("old suspopt")

    def run(fail: bool) -> None:
        with ExitStack() as stack:
            for path in (result, figure):
                stack.enter_context(io.claim(path))
            stack.enter_context(together([io._key(result), io._key(figure)], True, io.commit))
            for path in (figure, result):
                with io.atomic_file(path) as stream:
                    stream.write(b"new suspopt")
                assert path.read_text() == "old suspopt"  # (held to the end)
            if fail:
                raise RuntimeError("the command failed")

    with pytest.raises(RuntimeError):
        run(fail=True)
    assert [p.read_text() for p in (result, figure)] == ["old suspopt"] * 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.txt", "r.txt"]  # (no temp left)
    run(fail=False)
    assert [p.read_text() for p in (result, figure)] == ["new suspopt"] * 2


def test_a_result_that_lands_as_it_goes_takes_its_old_figure_when_it_has_no_new_one(tmp_path):
    """Not held (``optimise``'s checkpoints): the result lands when written; a run that ends
    without its figure (interrupted) removes the old one, which is of the old result."""
    from contextlib import ExitStack

    from suspopt import io
    from suspopt.replacing import together

    result, figure = tmp_path / "r.txt", tmp_path / "f.txt"
    for path in (result, figure):
        path.write_text("old suspopt")
    with pytest.raises(KeyboardInterrupt), ExitStack() as stack:
        for path in (result, figure):
            stack.enter_context(io.claim(path))
        stack.enter_context(together([io._key(result), io._key(figure)], False, io.commit))
        with io.atomic_file(result) as stream:
            stream.write(b"new suspopt")
        assert result.read_text() == "new suspopt"  # (landed at once)
        raise KeyboardInterrupt
    assert result.read_text() == "new suspopt" and not figure.exists()


def test_a_long_table_shows_its_first_rows_and_counts_the_rest(capsys, tmp_path):
    from suspopt.cli import base, summary

    def table():
        made = base.new_table("numbers")
        made.add_column("#")
        made.add_column("value")
        for i in range(40):
            made.add_row(str(i), f"{i * i}")
        return made

    base.show_table(table(), full=False, where=tmp_path / "n.h5")
    shown = capsys.readouterr().out
    rows = re.findall(r"^│ (\d+) ", shown, re.M)
    assert rows == [str(i) for i in range(summary.SUMMARY_ROWS)]
    left = 40 - summary.SUMMARY_ROWS
    assert (
        f"... {left} more rows: --full for all; the whole table is in {tmp_path / 'n.h5'}" in shown
    )
    base.show_table(table(), full=True)
    assert re.findall(r"^│ (\d+) ", capsys.readouterr().out, re.M) == [str(i) for i in range(40)]


def _narrow(monkeypatch) -> None:
    from rich.console import Console

    narrow = Console(width=80, markup=False, emoji=False, highlight=False)
    for name, module in list(sys.modules.items()):
        if name.startswith("suspopt.cli") and hasattr(module, "out"):
            monkeypatch.setattr(module, "out", narrow)


def _changes(stdout: str) -> list[str]:
    """The headers of the tolerance table's value columns as printed, in order."""
    return re.findall(r"([A-Za-z_0-9]+ [+-]\d+ %: [A-Za-z_0-9]+) \(change\)", stdout)


@pytest.mark.slow
def test_the_tolerance_table_is_summarised_and_full_prints_what_the_file_holds(
    front, tmp_path, capsys, monkeypatch
):
    _narrow(monkeypatch)
    monkeypatch.chdir(tmp_path)  # (a short name: the count line fits 80 columns)
    out = "tol.h5"
    code, summarised, err = cli(capsys, "analyse", "tolerances", front, "-o", out)
    assert code == 0, err
    code, whole, err = cli(capsys, "analyse", "tolerances", front, "-o", out, "--full")
    assert code == 0, err
    with h5py.File(out) as h5:
        labels = list(h5["pseudo"].attrs["labels"].astype(str))
        objectives = list(h5["pareto/F"].attrs["names"].astype(str))
    in_file = [f"{label}: {name}" for label in labels for name in objectives]
    assert _changes(whole) == in_file
    shown = _changes(summarised)
    assert shown == in_file[: len(shown)] and len(shown) < len(in_file)
    count = re.search(
        r"^\.\.\. (\d+) more parts? \((\d+) columns\): --full for all; (.*)$", summarised, re.M
    )
    assert count is not None, summarised
    assert int(count[2]) == len(in_file) - len(shown)
    assert count[3] == f"the whole table is in {out}"
    assert len(summarised.splitlines()) < len(whole.splitlines())


def _kind_help(capsys, monkeypatch, kind: str) -> str:
    monkeypatch.setenv("COLUMNS", "200")
    code, out, _ = cli(capsys, "analyse", kind, "--help")
    assert code == 0
    return " ".join(out.split())


@pytest.mark.parametrize("kind", sorted(SUMMARIES))
def test_each_analyse_kind_has_its_own_help_with_an_example(capsys, monkeypatch, kind):
    from suspopt.analyse import analysis_kinds
    from suspopt.cli.kinds import EXAMPLES

    assert set(EXAMPLES) == set(SUMMARIES)
    text = _kind_help(capsys, monkeypatch, kind)
    assert f"Usage: suspopt analyse {kind} SOURCE" in text
    assert SUMMARIES[kind].split(" (")[0] in text
    assert f"Example: {EXAMPLES[kind]}" in text
    flags = set(re.findall(r" (--[a-z-]+)", EXAMPLES[kind]))
    taken = {"--" + o.rstrip("_").replace("_", "-") for o in analysis_kinds()[kind].options}
    assert flags <= taken | {"--plot"}, flags - taken  # (the example takes the kind's own)


@pytest.mark.parametrize(
    "kind, own, not_own",
    [
        ("tolerances", "--tolerance", "--samples"),
        ("builds", "--samples", "--road"),
        ("roads", "--road", "--tolerance"),
        ("models", "--reference", "--pick"),
    ],
)
def test_a_kinds_help_lists_only_the_options_it_takes(capsys, monkeypatch, kind, own, not_own):
    text = _kind_help(capsys, monkeypatch, kind)
    assert own in text and not_own not in text
    assert "--output" in text and "--full" in text and "--force" in text
