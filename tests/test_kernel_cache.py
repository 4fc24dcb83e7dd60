"""The compiled kernel is compiled once per machine, not once per install
(docs/guide/engines.md#the-first-compiled-run-on-a-machine), and its compiles are said.

numba keys its own cache on the folder of the source file, so each virtual environment, wheel
or checkout of suspopt compiled the kernel again (a minute or more); suspopt's locator keeps
suspopt's compiled functions in the machine's cache under a digest of the code instead. The
command line shows a compile that lasts, on stderr, and nothing for a cache's quick load."""

from __future__ import annotations

import sys
import time
import types

import pytest

numba = pytest.importorskip("numba")

from suspopt import (
    _notices,  # noqa: E402
    _numba_cache,  # noqa: E402
)

SOURCE = "import numba\n\n@numba.njit(cache=True)\ndef add(x):\n    return x + 1\n"


def _install(root, name):
    """A copy of a package holding ``integrator/cached_add.py`` under ``root/name``."""
    folder = root / name / "integrator"
    folder.mkdir(parents=True)
    (folder / "cached_add.py").write_text(SOURCE)
    return folder / "cached_add.py"


def _load(path, monkeypatch):
    """``add`` of the module at ``path``, called once: whether it came from the cache."""
    module = types.ModuleType("cached_add")
    module.__file__ = str(path)
    monkeypatch.setitem(sys.modules, module.__name__, module)
    exec(compile(path.read_text(), str(path), "exec"), module.__dict__)
    assert module.add(1) == 2
    return sum(module.add.stats.cache_hits.values()) == 1


def test_two_installs_of_the_same_code_share_one_compile(monkeypatch, tmp_path):
    _numba_cache.prepare()
    monkeypatch.setenv("SUSPOPT_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(numba.config, "CACHE_DIR", "")
    first, second = _install(tmp_path, "venv1"), _install(tmp_path, "venv2")
    for install in (first, second):
        monkeypatch.setattr(_numba_cache, "_PACKAGE", install.parents[1])
        _numba_cache._digest.cache_clear()
        hit = _load(install, monkeypatch)
        assert hit == (install is second)  # (the second install: no compile)
    kept = list((tmp_path / "cache" / "numba").rglob("*.nbi"))
    assert len(kept) == 1 and kept[0].parent.name == "integrator"
    assert not (first.parent / "__pycache__").exists()  # (nothing beside the sources)
    # changed code compiles anew, in a folder of its own
    second.write_text(SOURCE.replace("x + 1", "1 + x"))
    _numba_cache._digest.cache_clear()
    assert not _load(second, monkeypatch)
    assert len(list((tmp_path / "cache" / "numba").rglob("*.nbi"))) == 2
    _numba_cache._digest.cache_clear()


def test_numbas_own_cache_folder_when_set_is_left_to_numba(monkeypatch, tmp_path):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    assert _numba_cache.kernel_cache() is None


def _notices_of(seconds: float) -> list[tuple[str, dict]]:
    told: list[tuple[str, dict]] = []

    def listener(kind, **data):
        told.append((kind, data))

    _notices.listen(listener)
    try:
        with _numba_cache.compiling("the simulation kernel"):
            with _numba_cache.compiling("an inner part"):  # (part of the outer stretch)
                time.sleep(seconds)
    finally:
        _notices.unlisten(listener)
    return told


def test_a_compile_is_told_once_with_its_time():
    told = _notices_of(0.05)
    assert [kind for kind, _ in told] == ["compile-start", "compile-end"]
    assert told[1][1]["what"] == "the simulation kernel" and told[1][1]["seconds"] >= 0.05


def test_the_command_line_shows_a_long_compile_and_not_a_quick_load(monkeypatch, capsys):
    from suspopt.cli import notices as shown

    monkeypatch.setattr(shown, "DELAY", 0.2)
    _notices.listen(shown.notices)
    try:
        with _numba_cache.compiling("a quick load"):
            time.sleep(0.01)
        with _numba_cache.compiling("the simulation kernel"):
            time.sleep(0.5)
    finally:
        _notices.unlisten(shown.notices)
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2, err  # (stderr is no terminal here: a line at the start and the end)
    assert err[0].startswith("compiling the simulation kernel, once for this machine")
    assert err[1].startswith("compiled the simulation kernel in 0.")
    assert "quick" not in "\n".join(err)


def test_auto_falling_back_is_one_note_on_the_command_line(capsys):
    from suspopt.cli.notices import notices

    notices("engine-fallback", message="simulation.engine auto runs on the numpy engine: x")
    assert capsys.readouterr().err == "note: simulation.engine auto runs on the numpy engine: x\n"


def test_a_damaged_file_of_numbas_cache_is_compiled_again_and_a_sound_one_is_read(
    monkeypatch, tmp_path
):
    """numba raised EOFError or an unpickling error on a truncated or overwritten file of its
    cache, in every later process, where a missing file makes it compile again; with
    ``_numba_cache.heal`` (which the compiled modules call) such a file is a miss, written
    anew, and a sound cache is still read (a hit, no compilation)."""
    _numba_cache.heal()
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "cache"))
    source = tmp_path / "cached_add.py"
    source.write_text(SOURCE)
    assert not _load(source, monkeypatch)  # (the first: compiled, and kept)
    assert _load(source, monkeypatch)
    for suffix, damage in ((".nbi", b""), (".nbi", b"\x80\x04garbage"), (".nbc", b"\x00")):
        (kept,) = (tmp_path / "cache").rglob(f"*{suffix}")
        kept.write_bytes(damage)
        assert not _load(source, monkeypatch)  # (compiled again, where numba raised)
        assert _load(source, monkeypatch)  # (and its cache written anew)
