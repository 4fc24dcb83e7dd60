"""The ``suspopt`` command's entry point: runs the CLI and turns what escapes it into exit
codes, with no traceback for anything but a bug.

- bad input (a usage error, a config, a file): one line ``error: ...``, exit 2;
- Ctrl-C at any moment, start-up included: ``interrupted``, exit 130 (an output being written
  is left as it was; ``suspopt optimise`` keeps what it found, see its help);
- SIGTERM (``kill``, a batch system's or CI's time limit) the same way: ``terminated``, exit
  143, outputs cleaned up and ``suspopt optimise``'s last generation kept, where Python's
  default would end the process at once, leaving a temporary file beside the output;
- a numpy floating-point warning: one line ``warning: ...`` per place, not a stack of them;
- anything else is a bug: its traceback and exit 1.

This module imports nothing heavy, so that even an interrupt during the imports lands here.
"""

from __future__ import annotations

import atexit
import contextlib
import gc
import os
import signal
import sys
import threading
import warnings

#: Exit code of an interrupted command (128 + SIGINT, as shells report it).
EXIT_INTERRUPTED = 130
#: Exit code of a terminated command (128 + SIGTERM).
EXIT_TERMINATED = 143


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    text = " ".join(str(message).split())
    place = filename.rsplit("/", 2)[-2:]
    sys.stderr.write(f"warning: {text} (at {'/'.join(place)}:{lineno})\n")


def _interrupted() -> int:
    if threading.current_thread() is threading.main_thread():
        for signum in (signal.SIGINT, signal.SIGTERM):  # a second one while leaving
            signal.signal(signum, signal.SIG_IGN)
    if _Interrupts.signum == signal.SIGTERM:
        sys.stderr.write("terminated\n")
        return EXIT_TERMINATED
    sys.stderr.write("interrupted\n")
    return EXIT_INTERRUPTED


class _Interrupts:
    """Notes that Ctrl-C was pressed or SIGTERM came (typer turns the KeyboardInterrupt into
    exit code 130 without a word), and which."""

    seen = False
    signum: int = signal.SIGINT

    @classmethod
    def handler(cls, signum, frame):
        cls.seen = True
        cls.signum = signum
        raise KeyboardInterrupt


def main(argv: list[str] | None = None, leaving: bool = False) -> int:
    """Run ``suspopt`` with ``argv`` (default the process's arguments); return its exit
    code. Ctrl-C's handling is put back as it was on return, unless the process is
    ``leaving`` (the command line's, which ignores a second Ctrl-C until it exits)."""
    _Interrupts.seen, _Interrupts.signum = False, signal.SIGINT
    main_thread = threading.current_thread() is threading.main_thread()
    found = signal.getsignal(signal.SIGINT)
    found_term = signal.getsignal(signal.SIGTERM) if main_thread else None
    if found is signal.default_int_handler:
        signal.signal(signal.SIGINT, _Interrupts.handler)
    if found_term == signal.SIG_DFL:
        signal.signal(signal.SIGTERM, _Interrupts.handler)
    try:
        warnings.showwarning = _one_line_warning
        warnings.simplefilter("default")  # each place once
        import typer

        from .cli import app

        try:
            code = app(args=argv, prog_name="suspopt", standalone_mode=False)
        except typer.Abort:  # click's form of a KeyboardInterrupt
            return _interrupted()
        except Exception as exc:
            if not (hasattr(exc, "format_message") and hasattr(exc, "exit_code")):
                raise  # a bug: its traceback
            # a usage error (click's, vendored by newer typer)
            message = " ".join(exc.format_message().split())
            if message:  # (no message: the help was shown)
                ctx = getattr(exc, "ctx", None)
                hint = f" (see {ctx.command_path} --help)" if ctx is not None else ""
                sys.stderr.write(f"error: {message}{hint}\n")
            return exc.exit_code
        if _Interrupts.seen:
            return _interrupted()
        return code if isinstance(code, int) else 0
    except KeyboardInterrupt:
        return _interrupted()
    finally:
        from .memory import set_limit

        set_limit(None)  # --max-memory holds for one command
        if not leaving and main_thread:
            if found is not None:
                signal.signal(signal.SIGINT, found)
            if found_term is not None:
                signal.signal(signal.SIGTERM, found_term)


#: BLAS thread pools the command line sizes to one thread, unless the user set them: the
#: model's products are tiny (a few rows by the batch), where a second BLAS thread only spins
#: (about 0.1 s of CPU at start-up alone) and competes with suspopt's own worker processes.
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def _replace_unencodable() -> None:
    """Where stdout or stderr does not take UTF-8 (``LANG=en_US.ISO-8859-1``,
    ``PYTHONIOENCODING=ascii``), print what it cannot encode (ε, ±, Γ) as ``?`` rather than
    fail with a UnicodeEncodeError traceback (``--help`` included)."""
    for stream in (sys.stdout, sys.stderr):
        encoding = (getattr(stream, "encoding", None) or "").lower().replace("-", "")
        if encoding != "utf8":
            reconfigure = getattr(stream, "reconfigure", None)  # (a TextIOWrapper's)
            if reconfigure is not None:
                with contextlib.suppress(ValueError, OSError):
                    reconfigure(errors="replace")


def run() -> None:
    """Console-script entry point (``suspopt`` and ``python -m suspopt``): one BLAS thread
    unless the environment says otherwise (:data:`BLAS_THREAD_VARIABLES`, set before numpy
    loads, and inherited by the worker processes), then :func:`main`."""
    for variable in BLAS_THREAD_VARIABLES:
        os.environ.setdefault(variable, "1")
    _replace_unencodable()
    # pydantic's plugins (looked up in every installed package's metadata, 7 ms) observe the
    # validation of suspopt's own config only: none is loaded unless the user asks for them
    os.environ.setdefault("PYDANTIC_DISABLE_PLUGINS", "__all__")
    # the start-up creates some 10^5 long-lived objects (the config's schema, the commands):
    # CPython's default first-generation threshold of 700 scans them over and over (0.04 s)
    gc.set_threshold(10_000, 10, 10)
    code = main(leaving=True)
    if code in (EXIT_INTERRUPTED, EXIT_TERMINATED):
        # CPython may remember an interrupt it saw inside C code even though it was caught,
        # and then end the process by SIGINT (status -2) instead of the code given: leave at
        # once, every output already cleaned up
        _flush()
        os._exit(code)
    if threading.active_count() == 1:
        # every output is written and closed when a command returns: run the exit handlers
        # (h5py's, temporary folders' finalisers, logging), flush, and leave without the
        # interpreter's teardown, which frees the start-up's 10^5 objects one by one (0.05 s)
        atexit._run_exitfuncs()
        _flush()
        os._exit(code)
    sys.exit(code)  # a thread still running: the interpreter joins it as usual


def _flush() -> None:
    """Flush stdout and stderr; a reader that went away (``suspopt schema | head``) is not an
    error of the command's."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError):
            stream.flush()
