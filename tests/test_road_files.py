"""The road profile reader: property tests (hypothesis) and its memory.

A well-formed profile is read by numpy's parser, any other line by line (the reference: it
names the first bad line). Over texts made of numbers of every form, separators, headers,
blank lines and every line break ``str.splitlines`` knows, the fast reading never accepts a
text the line-by-line reading rejects, and where it accepts one it gives the same numbers
bit for bit. The examples are derandomised: the same on every run. A large file with a bad
line is read within a bounded memory (each line was a Python object: 19 GB for 256 MB).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from suspopt.config import road

NUMBERS = st.sampled_from(
    ["0", "1", "-0", "2.5", " 3 ", "1e3", "1e400", "-1e-320", "nan", "inf", "1_0", "0x10", "", "x"]
) | st.floats(allow_nan=False, allow_infinity=False).map(repr)
SEPARATORS = st.sampled_from([",", ", ", " ,", ",,", ";", "\t"])
ROWS = st.tuples(NUMBERS, SEPARATORS, NUMBERS).map("".join)
LINES = ROWS | st.sampled_from(["distance,height", "", "   ", "# note", "0,1,2"])
BREAKS = st.sampled_from(["\n", "\n", "\n", "\r\n", "\r", "\x0c", "\u2028", "\x85"])
TEXTS = st.lists(st.tuples(LINES, BREAKS), max_size=12).map(
    lambda pairs: "".join(line + brk for line, brk in pairs)
)
#: increasing distances, so that well-formed texts are common
INCREASING = st.lists(st.floats(-1.0, 1.0), min_size=2, max_size=12).map(
    lambda heights: (
        "distance,height\n" + "".join(f"{i * 0.25!r},{h!r}\n" for i, h in enumerate(heights))
    )
)


def _line_by_line(text: str):
    try:
        return road._rows_line_by_line(Path("road.csv"), text, road._header(text))
    except ValueError as exc:
        return str(exc)


@pytest.mark.filterwarnings("error")  # (a warning is a line on the command line's stderr)
@settings(max_examples=400, deadline=None, derandomize=True, database=None)
@given(text=TEXTS | INCREASING | st.tuples(INCREASING, TEXTS).map("".join))
def test_the_fast_reading_agrees_with_the_line_by_line_one(text):
    data = text.encode("utf-8")
    fast = road._fast_rows(data, text, road._header(text))
    if fast is None:
        return  # read line by line, the reference
    reference = _line_by_line(text)
    assert not isinstance(reference, str), reference
    for column, values in zip(fast.T, reference):
        assert np.array_equal(column.view(np.int64), values.view(np.int64))


@pytest.mark.parametrize(
    "text, message",
    [
        ("0,0\n1,0\n1,5\n" + "2,0\n" * 1000, "road.csv:3: distances must increase strictly"),
        ("0,0\r1,0\r0.5,0\r", "road.csv:3: distances must increase strictly"),
        ("distance\x0c,height\n0,0\n1,0\n", "road.csv:2: expected two numbers"),
    ],
)
def test_the_first_bad_line_is_named_whichever_reading_is_tried(tmp_path, text, message):
    path = tmp_path / "road.csv"
    path.write_text(text, newline="")
    with pytest.raises(ValueError, match=message.replace(".", r"\.")):
        road.read_profile(path)


def test_a_well_formed_profile_is_read_with_its_header_and_windows_line_ends(tmp_path):
    path = tmp_path / "road.csv"
    path.write_bytes(b"distance,height\r\n0,0.001\r\n\r\n0.5,-0.002\r\n1.0,0\r\n")
    distance, height = road.read_profile(path)
    np.testing.assert_array_equal(distance, [0.0, 0.5, 1.0])
    np.testing.assert_array_equal(height, [0.001, -0.002, 0.0])


def test_a_large_profile_is_read_within_a_memory_cap_and_its_bad_line_named(tmp_path):
    """16 MB of rows '1,1' (the second line is bad) under an address-space cap of 300 MB
    above the reading process's start: the reading stops at the bad line (it made a Python
    object of every line first, about 1 GB: a MemoryError under the cap)."""
    path = tmp_path / "road.csv"
    path.write_text("1,1\n" * 4_000_000)
    code = (
        "import resource, sys\n"
        "from pathlib import Path\n"
        "import numpy\n"
        "from suspopt.config.road import read_profile\n"
        "held = int(open('/proc/self/statm').read().split()[0]) * resource.getpagesize()\n"
        "resource.setrlimit(resource.RLIMIT_AS, (held + (300 << 20), resource.RLIM_INFINITY))\n"
        "try:\n"
        "    read_profile(Path(sys.argv[1]))\n"
        "except ValueError as exc:\n"
        "    print(exc)\n"
    )
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    proc = subprocess.run(
        [sys.executable, "-c", code, str(path)], capture_output=True, text=True, env=env
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip() == f"road profile {path}:2: distances must increase strictly"
