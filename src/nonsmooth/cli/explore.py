"""`nonsmooth explore`: the interactive page (``nonsmooth.explore``) on a local server."""

from __future__ import annotations

from typing import Annotated, Optional

import typer

from .app import app
from .common import (DEFAULT_MODEL, MethodOpt, ModelOpt, PresetOpt, SetOpt, ShowOpt, load_params,
                     resolve_method)


@app.command("explore")
def explore_cmd(
    model: ModelOpt = DEFAULT_MODEL,
    preset: PresetOpt = None,
    set_: SetOpt = None,
    method: MethodOpt = None,
    show: ShowOpt = None,
    param: Annotated[Optional[str], typer.Option(
        "--param", show_default=False,
        help="parameter of the orbit-diagram slice (default: the forcing frequency)")] = None,
    host: Annotated[str, typer.Option(help="address to listen on")] = "127.0.0.1",
    port: Annotated[int, typer.Option(help="port (0: a free one, printed)")] = 0,
    no_browser: Annotated[bool, typer.Option("--no-browser",
                                             help="do not open a browser")] = False,
):
    """Open an interactive page in the browser: parameters, method and initial condition on
    the left; time response, phase portrait with the section and an orbit-diagram slice that
    follow them; export as a command line. Ctrl-C stops the server."""
    from ..errors import ParameterError
    from ..plot.common import check_show

    params = load_params(preset, set_, model, "table3", method=method)
    method = resolve_method(params, method)
    pair = check_show(show, params.model.state_names)
    if param is not None:
        params.model.param(param)  # one line naming the field
    if not 0 <= port <= 65535:
        raise ParameterError(f"port: must be between 0 and 65535, got {port}")
    from ..explore.server import serve
    serve(host=host, port=port or None, open_browser=not no_browser,
          log=lambda s: typer.echo(s, err=False), model=model, method=method,
          sets=params.as_dict(), show=pair, slice_param=param)
