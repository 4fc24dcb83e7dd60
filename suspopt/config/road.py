"""The ``road:`` section: discrete bumps, ISO 8608 random roads and measured profiles (Sec 2.5).

One model per ``kind``, joined in the discriminated union :data:`RoadConfig`. All quantities SI:
heights and lengths in m, speeds in m/s, times in s, spatial frequencies in cycles/m.

The ``tracks`` key, common to every kind, says what the left and right wheels see:

- ``identical`` (default): both sides drive over the same profile;
- ``independent``: the left side gets its own random realisation (``iso8608`` only);
- ``right_only`` / ``left_only``: the road acts on that side, the other side is flat (the thesis's
  Ch. 3 Part 2a puts the step under the right wheels only, Table 3.14).

A ``file`` road's relative ``path`` is resolved against the directory of the config file. The
loader passes that directory as the validation context (``context={"base_dir": ...}``); then a
missing file is reported on ``road.path`` at validation time. Without a context a relative path
is checked when the road is generated (:func:`suspopt.road.road_inputs` raises
``FileNotFoundError``).
"""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Annotated, Literal

from pydantic import Field, ValidationInfo, field_validator, model_validator

from ..files import Unreadable, read_bounded
from .base import RoadHeight, RoadLength, Section, Seed, Speed, bounds

__all__ = [
    "Tracks",
    "BumpStep",
    "BumpHalfSine",
    "Iso8608Road",
    "FileRoad",
    "RoadConfig",
    "resolve_road_file",
    "read_profile",
    "MAX_PROFILE_BYTES",
    "MAX_PROFILE_HEIGHT",
    "MAX_PROFILE_DISTANCE",
    "MAX_PROFILE_SLOPE",
    "MIN_BUMP_HEIGHT",
]

Tracks = Literal["identical", "independent", "right_only", "left_only"]

#: [s] when the front wheels reach a bump
_Start = Annotated[float, bounds(0.0, 1e5)]
#: [cycles/m] spatial frequencies, down to a 10 km wavelength and up to a 1 cm one
_SpatialFrequency = Annotated[float, bounds(1e-4, 100.0)]
_TRACKS_DESCRIPTION = (
    "what the two sides see: 'identical' (left = right), 'independent' (left is an independent "
    "realisation; iso8608 only), 'right_only' / 'left_only' (the other side is flat)"
)
_SPEED_DESCRIPTION = "constant vehicle speed V [m/s]"


class _Road(Section):
    """Fields every road kind has."""

    speed: Speed = Field(description=_SPEED_DESCRIPTION)
    tracks: Tracks = Field("identical", description=_TRACKS_DESCRIPTION)
    wheelbase_delay: bool = Field(
        True,
        description="rear wheels meet the road (a_F + a_R)/V "
        "after the front ones (Sec 2.5.2); false feeds both axles "
        "at once, e.g. to compare a half car with a quarter car",
    )


class _DeterministicRoad(_Road):
    """A road with a single, fixed shape: it has no second realisation for the left track."""

    @field_validator("tracks")
    @classmethod
    def _one_realisation(cls, tracks: str) -> str:
        if tracks == "independent":
            raise ValueError(
                "tracks 'independent' needs a random road (kind: iso8608); use "
                "'identical', 'right_only' or 'left_only'"
            )
        return tracks


#: The lowest bump [m]: anything lower is a flat road to the model (every signal at rest,
#: every objective 0 or, for a height like 1e-300 m, squared to nothing).
MIN_BUMP_HEIGHT = 1e-6


class _Bump(_DeterministicRoad):
    """A bump: its ``height`` is at least :data:`MIN_BUMP_HEIGHT` either way."""

    @field_validator("height", check_fields=False)
    @classmethod
    def _not_flat(cls, height: float) -> float:
        if abs(height) < MIN_BUMP_HEIGHT:
            raise ValueError(
                f"a bump of height {height:g} m is a flat road: give a height of at least "
                f"{MIN_BUMP_HEIGHT:g} m either way (negative for a pothole)"
            )
        return height


class BumpStep(_Bump):
    """Rectangular bump (step up, plateau, step down), Eq 2.103-2.104.

    A wheel is raised by ``height`` from ``start`` for ``length / speed`` seconds; the rear wheels
    see the same plateau delayed by the wheelbase over the speed (the printed rear duration
    ``L/(2V)`` is a slip: docs/thesis-slips.md#eq-2104).
    """

    kind: Literal["bump_step"] = Field(description="rectangular bump, Eq 2.103-2.104")
    height: RoadHeight = Field(description="plateau height h [m]; negative for a pothole")
    length: RoadLength = Field(
        description="length of the raised plateau on the road [m] (the "
        "thesis's L, Fig. 2.21); a wheel stays on it for length/speed s"
    )
    start: _Start = Field(description="time at which the front wheels reach the bump t0 [s]")


class BumpHalfSine(_Bump):
    """Half-sine bump, Eq 2.101-2.102 as corrected (slip: docs/thesis-slips.md#eq-2101).

    ``z = height sin(pi (t - start) V / length)`` for ``start <= t < start + length / V``,
    0 otherwise. ``length`` is the base length of the bump on the road, the thesis's ``L/2``.
    """

    kind: Literal["bump_half_sine"] = Field(description="half-sine bump, Eq 2.101-2.102")
    height: RoadHeight = Field(description="crest height h [m]; negative for a dip")
    length: RoadLength = Field(
        description="base length of the half-sine on the road L_b [m] "
        "(the thesis's L/2, slip: docs/thesis-slips.md#eq-2101); crossing "
        "lasts length/speed s"
    )
    start: _Start = Field(description="time at which the front wheels reach the bump t0 [s]")


class Iso8608Road(_Road):
    """Random road of ISO 8608 roughness by harmonic superposition, Eq 2.93, 2.97-2.100.

    ``convention`` is required on purpose: the two amplitude conventions differ by a factor
    ``sqrt(2 pi)`` (docs/iso-facts.md#amplitude-conventions) and must never be mixed silently.
    Use ``thesis`` in
    configs that reproduce the thesis's tables, ``iso8608`` for roads of the standard's roughness.
    """

    kind: Literal["iso8608"] = Field(description="ISO 8608 random road, Sec 2.5.1")
    road_class: Literal["A", "B", "C", "D", "E"] | None = Field(
        None,
        description="ISO 8608 class; sets G_d(n0) to the class's geometric mean "
        "(A 16, B 64, C 256, D 1024, E 4096 x 1e-6 m^3)",
    )
    level: Annotated[float, bounds(1e-12, 1.0)] | None = Field(
        None,
        description="displacement PSD level G_d(n0) at n0 = 0.1 cycles/m [m^3]; "
        "overrides road_class",
    )
    convention: Literal["iso8608", "thesis"] = Field(
        description="amplitude convention: 'iso8608' A_i = sqrt(2 G_d(n_i) dn) (one-sided PSD, "
        "the standard's meaning) or 'thesis' A_i = sqrt(Phi(Omega_i) dOmega / pi) (Eq 2.99; "
        "1/sqrt(2 pi) times smaller); G_d(n_i) dn and Phi(Omega_i) dOmega stand for the PSD's "
        "integral over harmonic i's cell"
    )
    waviness: Annotated[float, bounds(0.1, 10.0)] = Field(
        2.0, description="waviness w, the PSD slope exponent (Eq 2.93) [-]"
    )
    n_min: _SpatialFrequency = Field(
        0.011, description="lower edge of the generated band [cycles/m]"
    )
    n_max: _SpatialFrequency = Field(
        2.83, validate_default=True, description="upper edge of the generated band [cycles/m]"
    )
    n_waves: int | None = Field(
        None,
        ge=2,
        le=10_000_000,
        description="number of harmonics N, at the centres of N "
        "equal cells tiling n_min..n_max (not Eq 2.100's inclusive grid, see "
        "suspopt.road.iso8608_harmonics); default: the smallest N whose spacing "
        "(n_max - n_min)/N is at most 1/L, L the length of road the wheels travel [m], so the "
        "road does not repeat",
    )
    seed: Seed = Field(
        0,
        description="seed of the random phases; the same seed gives the "
        "same road bit for bit (default 0)",
    )

    @field_validator("n_max")
    @classmethod
    def _band_not_empty(cls, n_max: float, info: ValidationInfo) -> float:
        n_min = info.data.get("n_min")
        if n_min is not None and n_min >= n_max:
            raise ValueError(f"n_max ({n_max}) must be larger than n_min ({n_min})")
        return n_max

    @model_validator(mode="after")
    def _check_whole(self) -> Iso8608Road:
        # the band is checked again here for edits by assignment, which skip _band_not_empty
        if self.n_min >= self.n_max:
            raise ValueError(f"n_max ({self.n_max}) must be larger than n_min ({self.n_min})")
        if self.road_class is None and self.level is None:
            raise ValueError("give road_class (A-E) or level (G_d(n0) [m^3])")
        return self


class FileRoad(_DeterministicRoad):
    """Measured or designed profile read from a CSV file of distance [m], height [m].

    The file has two comma-separated columns and an optional header line. Heights are linearly
    interpolated; outside the file's distance range the road is flat at 0.
    """

    kind: Literal["file"] = Field(description="profile read from a CSV file")
    path: Path = Field(
        strict=False,
        description="CSV file with columns distance [m], height [m] and an "
        "optional header line; relative to the config file's directory",
    )
    scale: Annotated[float, bounds(-1e3, 1e3)] = Field(
        1.0, description="factor applied to the heights [-]"
    )

    @field_validator("path")
    @classmethod
    def _file_readable(cls, path: Path, info: ValidationInfo) -> Path:
        base_dir = (info.context or {}).get("base_dir")
        if not path.is_absolute() and base_dir is None:
            return path
        try:
            read_profile(_resolve(path, base_dir))
        except FileNotFoundError as exc:
            raise ValueError(str(exc)) from None
        return path


RoadConfig = Annotated[
    BumpStep | BumpHalfSine | Iso8608Road | FileRoad, Field(discriminator="kind")
]


def _resolve(path: Path, base_dir: Path | str | None) -> Path:
    """``path`` if absolute, else joined to ``base_dir`` (the current directory if None)."""
    return path if path.is_absolute() else Path(base_dir or ".") / path


def resolve_road_file(cfg: FileRoad, base_dir: Path | str | None) -> Path:
    """Path of a ``file`` road's CSV: absolute as given, relative to ``base_dir`` (the config
    file's directory), or to the current directory when ``base_dir`` is None. Existence is not
    checked here."""
    return _resolve(cfg.path, base_dir)


#: Largest road profile read [bytes]: 100 km at 1 cm spacing.
MAX_PROFILE_BYTES = 256 << 20
#: Largest height of a road profile, either way, before ``road.scale`` [m]: 1000 km, or 1 m
#: of a profile written in micrometres (``scale: 1.0e-6``).
MAX_PROFILE_HEIGHT = 1e6
#: Largest distance of a road profile, either way [m].
MAX_PROFILE_DISTANCE = 1e9
#: Steepest a road profile may rise or fall between two rows, before ``road.scale``: its
#: height change over its distance [m/m] (a 10 cm kerb over 0.1 um). The wheel's vertical
#: speed is this times the vehicle's; a steeper one (two rows 1e-300 m apart) overflows it.
MAX_PROFILE_SLOPE = 1e6


def read_profile(path: Path) -> tuple:
    """Distance [m] and height [m] columns ``(ndarray, ndarray)`` of a CSV road profile.

    The file is a regular UTF-8 text file of at most :data:`MAX_PROFILE_BYTES`, with an
    optional header line, then rows ``distance,height``: two finite numbers each, at least two
    rows, distances strictly increasing, within :data:`MAX_PROFILE_DISTANCE`, heights within
    :data:`MAX_PROFILE_HEIGHT`, no steeper than :data:`MAX_PROFILE_SLOPE` from one row to the
    next (a file of 1e308 heights gave the simulation overflows and NaN). ValueError (FileNotFoundError for a missing file)
    names the file and the line, never the line's content: the file may be anything.

    Its first 1000 lines are read line by line (a bad one is named at once); then a
    well-formed file is read by numpy's parser and any other line by line, which stops at its
    first bad line and names it, holding the numbers in compact arrays, never a Python object
    per line (``benchmarks/bench_road_file.py``).
    """
    try:
        data, text = _profile_text(path)
        header = _header(text)
        _rows_line_by_line(path, text, header, lines=1000)  # a bad line near the top, at once
        table = _fast_rows(data, text, header)
        if table is not None:
            return table[:, 0], table[:, 1]
        return _rows_line_by_line(path, text, header)
    except MemoryError:  # (under --max-memory, or a process's address-space limit)
        raise ValueError(
            f"road profile {path}: reading its {path.stat().st_size >> 20} MB ran out of memory"
        ) from None


def _profile_text(path: Path) -> tuple[bytes, str]:
    """The bytes of the road profile ``path`` and their UTF-8 text (see :func:`read_profile`;
    :func:`suspopt.files.read_bounded` refuses what is not a regular file of at most
    :data:`MAX_PROFILE_BYTES`)."""
    try:
        data = read_bounded(path, MAX_PROFILE_BYTES)
    except FileNotFoundError:
        raise FileNotFoundError(f"road profile file not found: {path}") from None
    except Unreadable as exc:
        raise ValueError(f"road profile {path}: {exc}") from None
    try:
        return data, data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise ValueError(f"road profile {path}:{line}: not UTF-8 text") from None


def _header(text: str) -> int:
    """1 when the first line of ``text`` is not a row of two numbers (a header), else 0."""
    return 1 if _row(next(_lines(text), "")) is None else 0


#: Line breaks of ``str.splitlines`` other than ``\n`` and ``\r\n``: a file holding one is
#: read line by line, where the lines are counted as ``splitlines`` counts them.
_OTHER_BREAKS = re.compile("\r(?!\n)|[\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029]")
_BREAKS = re.compile("\r\n|[\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029]")


def _fast_rows(data: bytes, text: str, header: int):
    """The ``(N, 2)`` rows of a well-formed profile (``data``, whose text is ``text``) by
    numpy's parser, or None when it is anything else (the line-by-line reading then finds
    and names its bad line)."""
    import io
    import warnings

    import numpy as np

    if _OTHER_BREAKS.search(text):
        return None
    try:
        with np.errstate(over="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")  # ("input contained no data": read line by line)
            table = np.loadtxt(
                io.BytesIO(data),
                delimiter=",",
                skiprows=header,
                ndmin=2,
                comments=None,
                encoding="utf-8",
            )
    except (ValueError, TypeError, MemoryError):
        return None
    if table.shape[1] != 2 or len(table) < 2 or not np.isfinite(table).all():
        return None
    distance, height = table[:, 0], table[:, 1]
    ok = (
        bool((np.abs(distance) <= MAX_PROFILE_DISTANCE).all())
        and bool((np.abs(height) <= MAX_PROFILE_HEIGHT).all())
        and bool((np.diff(distance) > 0).all())
        and bool((np.abs(np.diff(height)) <= MAX_PROFILE_SLOPE * np.diff(distance)).all())
    )
    return table if ok else None


def _lines(text: str):
    """The lines of ``text`` as ``str.splitlines`` gives them, one at a time."""
    start = 0
    for found in _BREAKS.finditer(text):
        yield text[start : found.start()]
        start = found.end()
    if start < len(text):
        yield text[start:]


def _rows_line_by_line(path: Path, text: str, header: int, lines: int | None = None) -> tuple:
    """The distance and height columns of the profile ``text``, read line by line; ValueError
    at its first bad line. With ``lines``, only that many lines are read (and not counted)."""
    from array import array
    from itertools import islice

    import numpy as np

    distance, height = array("d"), array("d")
    for number, line in enumerate(islice(_lines(text), lines), start=1):
        if number <= header or not line.strip():
            continue
        row = _row(line)
        if row is None:
            raise ValueError(
                f"road profile {path}:{number}: expected two numbers "
                f"'distance,height' separated by a comma"
            )
        if not (math.isfinite(row[0]) and math.isfinite(row[1])):
            raise ValueError(f"road profile {path}:{number}: values must be finite")
        if not abs(row[0]) <= MAX_PROFILE_DISTANCE:
            raise ValueError(
                f"road profile {path}:{number}: distances must be within "
                f"±{MAX_PROFILE_DISTANCE:g} m"
            )
        if not abs(row[1]) <= MAX_PROFILE_HEIGHT:
            raise ValueError(
                f"road profile {path}:{number}: heights must be within "
                f"±{MAX_PROFILE_HEIGHT:g} m (before road.scale)"
            )
        if distance and not row[0] > distance[-1]:
            raise ValueError(f"road profile {path}:{number}: distances must increase strictly")
        if distance and abs(row[1] - height[-1]) > MAX_PROFILE_SLOPE * (row[0] - distance[-1]):
            raise ValueError(
                f"road profile {path}:{number}: the height changes by more than "
                f"{MAX_PROFILE_SLOPE:g} times the distance from the row before (too steep)"
            )
        distance.append(row[0])
        height.append(row[1])
    if len(distance) < 2 and lines is None:
        raise ValueError(
            f"road profile {path}: needs at least two rows of 'distance,height', "
            f"found {len(distance)}"
        )
    return np.array(distance), np.array(height)


def _row(line: str) -> tuple[float, float] | None:
    """The two numbers of a CSV row, or None if it is not two numbers."""
    fields = line.split(",")
    if len(fields) != 2:
        return None
    try:
        return float(fields[0]), float(fields[1])
    except ValueError:
        return None
