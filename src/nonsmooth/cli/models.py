"""`nonsmooth models`: the built-in models, or one model (built-in or a user's script) in
detail."""

from __future__ import annotations

from typing import Annotated, Optional

import typer

from .app import app


def _value(v) -> str:
    return "required" if v is None else f"{v:g}"


def _contact_line(m) -> str:
    """What counts as contact in the results' ``contact`` variable of model ``m``."""
    if m.contact is not None or m.contact_name != "contact":
        return m.contact_name
    if m.contact_modes:
        return f"a visit of {m.contact_text}"
    return ("not defined (no contact_modes or contact function declared: the results' "
            "contact is 0)")


def model_lines(name: str) -> list[str]:
    """One model in detail: parameters (default, range, units, long name), state, modes,
    methods, presets, references."""
    from ..models import model

    m = model(name)
    out = [f"{m.name}: {m.description}", f"  source: {m.source}", "", "parameters:"]
    w = max(len(p.name) for p in m.parameters)
    for p in m.parameters:
        out.append(f"  {p.name:{w}s}  default {_value(p.default):>9s}  {p.range_text:28s}  "
                   f"{'[' + p.units + ']':9s}  {p.long_name}")
    amp = f", amplitude: {m.forcing_amplitude}" if m.forcing_amplitude else ""
    out.append(f"  forcing frequency: {m.omega}{amp}" if m.omega else
               f"  forcing period: {m.period}{amp}" if m.period else
               "  no forcing (self-excited; time unit 2 pi)")
    state = ", ".join(f"{s} ({ln})" if ln else s for s, ln in
                      zip(m.state_names, tuple(m.state_long_names) + ("",) * m.n))
    out += ["", f"state: {state}",
            "modes: " + ", ".join(f"{i} {nm}" for i, nm in enumerate(m.mode_names)),
            f"contact: {_contact_line(m)}", "", "methods:"]
    width = max(map(len, m.methods))
    for k, meth in m.methods.items():
        modes = ", ".join(m.mode_names[i] for i in meth.modes) if meth.modes else "all"
        out.append(f"  {k:{width}s} {meth.description or '(no description)'} (modes: {modes})")
    out += ["", "presets (--preset NAME):"]
    for k, (values, text) in m.presets.items():
        vals = ", ".join(f"{a}={b:g}" for a, b in values.items())
        out.append(f"  {k}: {text} ({vals})")
    if not m.presets:
        out.append("  none (the defaults above)")
    out += ["", "references:"] + [f"  {r}" for r in m.references or ("none",)]
    return out


@app.command("models")
def models_cmd(
    name: Annotated[Optional[str], typer.Argument(
        metavar="NAME", show_default=False,
        help="a built-in model or path/to/file.py:NAME: show it in detail")] = None,
):
    """List the built-in models (name, description, parameters with defaults and ranges), or
    show one in detail; use one with --model NAME on any command."""
    if name is not None:
        for line in model_lines(name):
            typer.echo(line)
        return
    from ..models import model, models

    for k in models():
        m = model(k)
        typer.echo(f"{m.name}: {m.description}")
        typer.echo(f"  methods: {', '.join(m.methods)}; modes: {', '.join(m.mode_names)}")
        typer.echo("  parameters: " + ", ".join(
            f"{p.name}={_value(p.default)} ({p.range_text})" for p in m.parameters))
    typer.echo("details: nonsmooth models NAME; your own model: --model path/to/file.py:NAME")
