"""The signature of the configs suspopt writes (``init``, ``export -o``).

Such a config ends in one comment line, ``# suspopt VERSION sha256 DIGEST: ...``, where
DIGEST is the SHA-256 of the lines above it. A config is suspopt's to replace (without
``--force``) only while that holds: once the user edits it, it is theirs
(:func:`suspopt.io.is_suspopt_output`).
"""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

from ._version import __version__
from .config.yamlio import MAX_CONFIG_BYTES

__all__ = ["CONFIG_SUFFIXES", "signed_config", "signature_state"]

#: The signature line (module docstring).
_SIGNATURE_LINE = re.compile(rb"^# suspopt \S+ sha256 ([0-9a-f]{64})[^\n]*$", re.MULTILINE)
CONFIG_SUFFIXES = (".yaml", ".yml")


def signed_config(text: str) -> str:
    """``text`` (a config suspopt writes) with its signature as the last line, in place of
    one it had (a config written from a signed config's text)."""
    lines = text.rstrip("\n").split("\n")
    while lines and _SIGNATURE_LINE.fullmatch(lines[-1].encode()):
        lines.pop()
    body = "\n".join(lines) + "\n"
    digest = hashlib.sha256(body.encode()).hexdigest()
    return body + f"# suspopt {__version__} sha256 {digest}: edited, replaced only with --force\n"


def signature_state(path: Path, size: int) -> bool | None:
    """Whether the config ``path`` is as suspopt signed it: True when its last line is a
    signature matching the lines above, False when it holds a signature but has been edited
    (lines changed, or added after the signature), None when it holds none."""
    if size > MAX_CONFIG_BYTES:  # (larger than any config suspopt reads)
        with open(path, "rb") as stream:
            stream.seek(size - 200)
            return False if _SIGNATURE_LINE.search(stream.read()) else None
    with open(path, "rb") as stream:
        data = stream.read(MAX_CONFIG_BYTES)
    found = [*_SIGNATURE_LINE.finditer(data)]
    if not found:
        return None
    last = found[-1]
    if data[last.end() :].strip(b"\n"):
        return False
    return hashlib.sha256(data[: last.start()]).hexdigest() == last[1].decode()
