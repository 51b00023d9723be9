"""Every command's --help: flags are shown as flags (no "<bool>" value that the parser would
then refuse)."""

import re

import pytest
from typer.testing import CliRunner

from nonsmooth.cli import app

COMMANDS = ["simulate", "presets", "poincare", "bifurcation", "resonance", "basins", "eta-study",
            "reproduce", "lyapunov", "orbit", "continue"]


@pytest.mark.parametrize("command", COMMANDS)
def test_help_shows_no_bool_metavar(command):
    res = CliRunner().invoke(app, [command, "--help"], env={"COLUMNS": "200"})
    assert res.exit_code == 0, res.output
    assert "<bool>" not in res.output
    assert re.search(r"--help\b", res.output)
