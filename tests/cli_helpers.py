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
