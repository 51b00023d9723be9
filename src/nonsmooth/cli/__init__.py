"""Command-line interface. ``main()`` turns errors into one line on stderr and an exit status
(README, "Exit codes"): 2 for bad input (typer's usage errors too), 3 for a numerical failure,
130 for Ctrl-C and 143 for SIGTERM, with one line saying what was saved and what was lost."""

from __future__ import annotations

import os
import signal
import sys

import typer

from .. import _numba_cache
from ..errors import IntegrationError, NonsmoothError, ParameterError
from .app import EXIT_INTERRUPTED, EXIT_NUMERICAL, EXIT_USAGE, Interrupted, Terminated, app
from .common import planned

# Each command module registers its commands on ``app`` when imported.
from . import simulate  # noqa: E402,F401
from . import eta_study  # noqa: E402,F401
from . import analyses  # noqa: E402,F401
from . import reproduce  # noqa: E402,F401
from . import basins  # noqa: E402,F401
from . import models  # noqa: E402,F401
from . import stability  # noqa: E402,F401
from . import continuation  # noqa: E402,F401
from . import parameter_map  # noqa: E402,F401
from . import autonomous  # noqa: E402,F401
from . import manifolds  # noqa: E402,F401
from . import explore  # noqa: E402,F401

def _terminate(signum, frame):
    # a second SIGTERM while the first unwinds (``timeout``, then a harness, or a supervisor
    # repeating it) is ignored: it would otherwise break the line on what was saved with a
    # traceback; ``main`` restores the previous handler
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    raise Terminated()


def _compile_notice() -> None:
    # the same rule as the progress bars (sweep.Progress): on a terminal, or when asked for
    if os.environ.get("NONSMOOTH_PROGRESS", "") == "1" or sys.stderr.isatty():
        typer.echo("compiling numba kernels (first run only, three to five minutes)...", err=True)


def interrupted_message(code: int) -> str:
    """What an interrupted run saved (the files written so far) and what it lost."""
    from ..io import written_files

    written = written_files()
    untouched = [p for p in planned.values() if p not in written]
    saved = (", ".join(map(str, written)) if len(written) <= 4 else
             f"{len(written)} files ({written[0]} ... {written[-1]})") or "nothing"
    lost = "the computation in progress; no partial result written"
    if untouched:
        lost += "; " + ", ".join(f"{p} {'untouched' if p.exists() else 'not written'}"
                                 for p in untouched)
    what = "interrupted" if code == EXIT_INTERRUPTED else "terminated"
    from ..chunks import active_stores, saved_chunks
    stores = [(p, n) for p, n in active_stores if p.is_dir()]
    if stores:
        path, total = stores[-1]
        chunks = f"{saved_chunks(path)} of {total} chunks in {path}"
        saved = chunks if saved == "nothing" else f"{saved}, {chunks}"
        lost = ("the chunks in progress" + lost.removeprefix(
            "the computation in progress; no partial result written") +
            "; run the same command again to resume")
    return f"{what}: saved {saved}; lost {lost}"


def _resume_notice(path, done: int, total: int) -> None:
    typer.echo(f"resuming from {path}: {done} of {total} chunks already done", err=True)


#: click's exception classes as typer raises them (typer vendors click since 0.2x: found by
#: name among the bases of its public ``BadParameter``)
_USAGE_ERROR, _CLICK_EXCEPTION = (next(c for c in typer.BadParameter.__mro__ if c.__name__ == n)
                                  for n in ("UsageError", "ClickException"))


def main(argv: list[str] | None = None) -> None:
    from .. import chunks
    planned.clear()
    chunks.active_stores.clear()
    chunks.on_resume = _resume_notice
    previous = signal.signal(signal.SIGTERM, _terminate)
    _numba_cache.compile_notice = _compile_notice
    args = sys.argv[1:] if argv is None else list(argv)
    try:
        if any(a == "--transition" or a.startswith("--transition=") for a in args):
            raise ParameterError("transition: the option is gone; eq. 12 is the support model's "
                                 "method: --method smooth_eq12 (eq. 13 is --method smooth)")
        rv = app(args=args, prog_name="nonsmooth", standalone_mode=False)
        sys.exit(rv if isinstance(rv, int) else 0)
    except _USAGE_ERROR as exc:  # an unknown option or command, a value of the wrong type
        if type(exc).__name__ != "NoArgsIsHelpError":  # (typer has shown the help then)
            # one line, like every other bad input
            ctx = getattr(exc, "ctx", None)
            where = f" (see '{ctx.command_path} --help')" if ctx is not None else ""
            typer.echo(f"error: {exc.format_message()}{where}", err=True)
        sys.exit(EXIT_USAGE)
    except typer.Abort:  # (what click's standalone mode prints)
        typer.echo("Aborted!", err=True)
        sys.exit(1)
    except _CLICK_EXCEPTION as exc:
        typer.echo(f"error: {exc.format_message()}", err=True)
        sys.exit(exc.exit_code)
    except Interrupted as exc:
        typer.echo(interrupted_message(exc.code), err=True)
        sys.exit(exc.code)
    except IntegrationError as exc:
        typer.echo(f"error: {exc}", err=True)
        sys.exit(EXIT_NUMERICAL)
    except NonsmoothError as exc:
        typer.echo(f"error: {exc}", err=True)
        sys.exit(EXIT_USAGE)
    finally:  # leave a calling process (tests, a notebook) as it was
        signal.signal(signal.SIGTERM, previous)
        _numba_cache.compile_notice = None
        chunks.on_resume = None
