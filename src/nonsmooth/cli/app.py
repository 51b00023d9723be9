"""The typer application. Command modules import ``app`` from here and register with
``@app.command("name")``; ``cli/__init__.py`` imports every command module."""

from typing import Annotated

import typer

from .._version import __version__

app = typer.Typer(
    name="nonsmooth",
    help="Nonlinear dynamics of the oscillator with a discontinuous support (switch model and exact).",
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
)


def _show_version(value: bool):
    if value:
        typer.echo(f"nonsmooth {__version__}")
        raise typer.Exit()


@app.callback()
def _main(version: Annotated[bool, typer.Option("--version", callback=_show_version, is_eager=True,
                                                help="print the version and exit")] = False):
    """Nonlinear dynamics of the oscillator with a discontinuous support (switch model and exact)."""
