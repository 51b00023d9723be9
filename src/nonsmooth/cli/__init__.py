"""Command-line interface. ``main()`` turns user errors into one line on stderr and exit 2
(usage errors are reported by typer itself, also with exit 2)."""

from __future__ import annotations

import sys

import typer

from ..errors import NonsmoothError
from .app import app

# Each command module registers its commands on ``app`` when imported.
from . import simulate  # noqa: E402,F401
from . import eta_study  # noqa: E402,F401
from . import analyses  # noqa: E402,F401
from . import reproduce  # noqa: E402,F401
from . import basins  # noqa: E402,F401


def main(argv: list[str] | None = None) -> None:
    try:
        app(args=argv, prog_name="nonsmooth")
    except NonsmoothError as exc:
        typer.echo(f"error: {exc}", err=True)
        sys.exit(2)
    except KeyboardInterrupt:
        typer.echo("interrupted", err=True)
        sys.exit(130)
