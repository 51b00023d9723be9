"""Helpers shared by the CLI tests: run ``nonsmooth.cli.main`` in-process and check errors."""

import pytest

from nonsmooth.cli import main


def run_cli(argv, capsys):
    """(exit code, stdout, stderr) of ``nonsmooth ARGV`` run in this process."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    cap = capsys.readouterr()
    return exc.value.code or 0, cap.out, cap.err


def one_line(err: str, needle: str) -> None:
    """stderr is exactly one ``error: ...`` line containing ``needle``."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0], lines


# -- real subprocesses and signals ---------------------------------------------------------------
import signal  # noqa: E402
import subprocess  # noqa: E402
import time  # noqa: E402

#: Safety limit of every wait on a child process: generous, so that an empty numba cache on a
#: loaded 2-core machine never reaches it; no test depends on its value (tests wait for an
#: observable state, a line or a file, and speed is measured in benchmarks/bench_interrupt.py).
SAFETY_S = 900


def _default_sigint():
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def popen(args, **kw):
    """``subprocess.Popen`` with SIGINT at its default in the child: a test run started as a
    background job of a non-interactive shell inherits SIGINT ignored, and its children would
    then ignore Ctrl-C as well (POSIX)."""
    return subprocess.Popen(args, preexec_fn=_default_sigint, **kw)


def wait_until(proc, ready, what: str) -> None:
    """Poll until ``ready()`` holds (an observable state: a line, a file); fail at once if the
    process ends first, and past ``SAFETY_S`` (a hang)."""
    t_end = time.monotonic() + SAFETY_S
    while not ready():
        if proc.poll() is not None:
            pytest.fail(f"the process ended (exit {proc.returncode}) before {what}")
        if time.monotonic() > t_end:
            proc.kill()
            pytest.fail(f"{what}: not seen within {SAFETY_S} s")
        time.sleep(0.02)
