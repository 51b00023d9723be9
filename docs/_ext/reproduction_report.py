"""Sphinx extension: the paper's reproduction report (``nonsmooth reproduce --quick``), run
once per package version into ``docs/_generated/extra/reproduction`` and copied into the site
(``html_extra_path``) as ``reproduction/report.html``; ``reproduction.md`` includes its
summary table."""

from __future__ import annotations

import json
from pathlib import Path

from sphinx.util import logging

LOG = logging.getLogger(__name__)


def _up_to_date(out: Path, version: str) -> bool:
    summary = out / "summary.json"
    if not (out / "report.html").is_file() or not summary.is_file():
        return False
    try:
        runs = json.loads(summary.read_text())
    except ValueError:
        return False
    return version in json.dumps(runs)


def generate(app) -> None:
    import nonsmooth as ns

    out = Path(app.srcdir) / "_generated" / "extra" / "reproduction"
    if _up_to_date(out, ns.__version__):
        LOG.info("reproduction report: up to date in %s", out)
        return
    out.mkdir(parents=True, exist_ok=True)
    LOG.info("reproduction report: running nonsmooth reproduce --quick (once per version) ...")
    ns.reproduce(out=out, quick=True, command="nonsmooth reproduce --quick (docs build)")


def setup(app):
    app.connect("builder-inited", generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
