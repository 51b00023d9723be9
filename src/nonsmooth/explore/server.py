"""Serving the explore page: a Bokeh server on one local address, stopped by Ctrl-C."""

from __future__ import annotations

import errno
import socket

from ..errors import OutputError


def free_port(host: str = "127.0.0.1") -> int:
    """A port nobody listens on now (the OS's choice)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]


def check_port(host: str, port: int) -> None:
    """A one-line OutputError if ``host:port`` cannot be listened on (in use, not allowed)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)   # as tornado binds
        try:
            s.bind((host, port))
        except OSError as exc:
            why = "in use" if exc.errno == errno.EADDRINUSE else exc.strerror
            raise OutputError(f"port: cannot listen on {host}:{port} ({why})") from None


def make_server(host: str = "127.0.0.1", port: int | None = None, **page_kw):
    """A Bokeh server (not started) whose page at ``/`` is ``make_document(doc, **page_kw)``;
    ``port`` None or 0 takes a free one. Returns (server, url)."""
    from bokeh.application import Application
    from bokeh.application.handlers.function import FunctionHandler
    from bokeh.server.server import Server

    from .page import make_document

    if not port:
        port = free_port(host)
    check_port(host, port)
    app = Application(FunctionHandler(lambda doc: make_document(doc, **page_kw)))
    origins = [f"{host}:{port}", f"localhost:{port}", f"127.0.0.1:{port}"]
    server = Server({"/": app}, address=host, port=port, allow_websocket_origin=origins,
                    num_procs=1)
    return server, f"http://{host}:{port}/"


def serve(host: str = "127.0.0.1", port: int | None = None, open_browser: bool = True,
          log=print, **page_kw) -> None:
    """Serve the explore page until Ctrl-C (then stop cleanly and return)."""
    import signal
    import threading

    server, url = make_server(host, port, **page_kw)
    if threading.current_thread() is threading.main_thread():
        # as servers do: Ctrl-C (SIGINT) stops it even where the shell that started it in
        # the background set SIGINT to be ignored
        signal.signal(signal.SIGINT, signal.default_int_handler)
    server.start()
    log(f"nonsmooth explore: {url}  (Ctrl-C stops it)")
    if open_browser:
        server.io_loop.add_callback(server.show, "/")
    try:
        server.io_loop.start()
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
        server.io_loop.stop()
    log("nonsmooth explore: stopped")
