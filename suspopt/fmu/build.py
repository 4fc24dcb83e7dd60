"""The FMU's binary for this platform, compiled from its sources with the system C compiler.

The compiler is ``$CC`` or the first of ``cc``, ``gcc`` and ``clang`` on the ``PATH``; the
flags ask for strict IEEE arithmetic (no fused multiply-adds, no fast math), so that the
binary computes what the sources say. Without a compiler (or on a platform without a folder
name here) the FMU is source-only: any tool that imports FMUs can compile ``sources/``.
"""

from __future__ import annotations

import os
import platform
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

__all__ = ["compiler", "platform_folder", "compile_binary"]

#: The flags of every build.
FLAGS = ["-shared", "-fPIC", "-O2", "-std=c99", "-ffp-contract=off", "-fvisibility=hidden"]


def compiler() -> str | None:
    """The C compiler to use, or None."""
    given = os.environ.get("CC")
    if given and shutil.which(given.split()[0]):
        return given
    for name in ("cc", "gcc", "clang"):
        if shutil.which(name):
            return name
    return None


def platform_folder() -> tuple[str, str] | None:
    """``binaries/<folder>`` and the shared library's suffix of this platform (FMI 2.0
    names), or None."""
    bits = "64" if sys.maxsize > 2**32 else "32"
    system = platform.system()
    if system == "Linux":
        return f"linux{bits}", ".so"
    if system == "Darwin":
        return f"darwin{bits}", ".dylib"
    return None


def compile_binary(sources: dict[str, bytes], compiled: tuple[str, ...], identifier: str):
    """The shared library of ``sources`` (file name -> contents; ``compiled`` the units to
    compile) as ``(path in the FMU, bytes)``, or ``(None, why not)``."""
    cc, where = compiler(), platform_folder()
    if where is None:
        return None, f"no FMI binary folder for {platform.system()}"
    if cc is None:
        return None, "no C compiler (cc, gcc or clang) found"
    folder, suffix = where
    with tempfile.TemporaryDirectory(prefix="suspopt-fmu-") as tmp:
        for name, data in sources.items():
            Path(tmp, name).write_bytes(data)
        target = Path(tmp, identifier + suffix)
        command = cc.split() + FLAGS + ["-o", str(target)] + list(compiled) + ["-lm"]
        try:
            done = subprocess.run(command, cwd=tmp, capture_output=True, text=True, timeout=600)
        except (OSError, subprocess.TimeoutExpired) as exc:
            return None, f"{cc} failed to run ({exc})"
        if done.returncode != 0 or not target.exists():
            first = (done.stderr.strip().splitlines() or ["no message"])[0]
            return None, f"{cc} failed: {first}"
        return (f"binaries/{folder}/{identifier}{suffix}", target.read_bytes()), cc
