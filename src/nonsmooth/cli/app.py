"""The typer application. Command modules import ``app`` from here and register with
``@app.command("name")``; ``cli/__init__.py`` imports every command module."""

import typer

app = typer.Typer(
    name="nonsmooth",
    help="Nonlinear dynamics of the oscillator with a discontinuous support (switch model and exact).",
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
)
