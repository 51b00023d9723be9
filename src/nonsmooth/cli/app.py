"""The typer application. Command modules import ``app`` from here and register with
``@app.command("name")``; ``cli/__init__.py`` imports every command module."""

from typing import Annotated

import typer
from typer.core import TyperGroup, TyperOption

from .._version import __version__

#: Exit statuses (README, "Exit codes").
EXIT_USAGE = 2
EXIT_NUMERICAL = 3
EXIT_INTERRUPTED = 130
EXIT_TERMINATED = 143


class Interrupted(Exception):
    """A command stopped by SIGINT (Ctrl-C) or SIGTERM; ``code`` is the exit status."""

    def __init__(self, code: int):
        super().__init__(code)
        self.code = code


class Terminated(KeyboardInterrupt):
    """Raised by the CLI's SIGTERM handler: a termination takes the Ctrl-C path."""


class _Group(TyperGroup):
    # typer turns a KeyboardInterrupt inside a command into a silent exit 130; pass it on to
    # main() instead, which says what was saved and what was lost
    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt as exc:
            code = EXIT_TERMINATED if isinstance(exc, Terminated) else EXIT_INTERRUPTED
            raise Interrupted(code) from None


def _flag_type(self, ctx):
    # a flag takes no value: typer's rich help would show "--quick <bool>" although
    # "--quick true" is an error
    return None if self.is_flag else _option_type(self, ctx)


_option_type = TyperOption.display_type_rich
TyperOption.display_type_rich = _flag_type

app = typer.Typer(
    cls=_Group,
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
