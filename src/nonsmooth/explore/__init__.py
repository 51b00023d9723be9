"""``nonsmooth explore``: an interactive page in the browser (a Bokeh server application).

Move a parameter and watch the time response, the phase portrait with its section points and an
orbit-diagram slice change; click in the orbit diagram to set the parameter, in the phase plane
to set the initial condition; export the settings as a command line and a Python snippet.

``compute`` holds what is computed (no page), ``page`` the Bokeh document, ``server`` the
server. Needs ``bokeh`` (a dependency of the package).
"""

from __future__ import annotations

__all__ = ["make_document", "serve"]


def make_document(doc, **kw):
    """Build the explore page in a Bokeh document (see :func:`nonsmooth.explore.page.make_document`)."""
    from .page import make_document as _make
    return _make(doc, **kw)


def serve(host: str = "127.0.0.1", port: int | None = None, open_browser: bool = True, **kw):
    """Serve the explore page on ``host:port`` (a free port if None) until Ctrl-C
    (see :func:`nonsmooth.explore.server.serve`)."""
    from .server import serve as _serve
    return _serve(host=host, port=port, open_browser=open_browser, **kw)
