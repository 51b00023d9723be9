"""Sphinx extension: the paper's reproduction report (``nonsmooth reproduce --quick``), run
once per package version into ``docs/_generated/extra/reproduction`` and copied into the site
(``html_extra_path``) as ``reproduction/report.html``; ``reproduction.md`` includes its
summary table."""

from __future__ import annotations

import json
from pathlib import Path

from sphinx.util import logging

LOG = logging.getLogger(__name__)


def _key() -> str:
    """The package version, a digest of its compiled sources (``_numba_cache``) and of the
    reproduction's own: a report computed by other code is run again."""
    import hashlib

    import nonsmooth as ns
    from nonsmooth._numba_cache import source_digest

    h = hashlib.sha256()
    for path in sorted((Path(ns.__file__).parent / "reproduction").rglob("*.py")):
        h.update(path.read_bytes())
    return f"{ns.__version__}+{source_digest()}+{h.hexdigest()[:16]}"


def generate(app) -> None:
    import nonsmooth as ns

    out = Path(app.srcdir) / "_generated" / "extra" / "reproduction"
    stamp = out / "docs-build.json"
    key = _key()
    try:
        same = json.loads(stamp.read_text()).get("key") == key and (out / "report.md").is_file()
    except (OSError, ValueError):
        same = False
    if same:
        LOG.info("reproduction report: up to date in %s", out)
        return
    out.mkdir(parents=True, exist_ok=True)
    LOG.info("reproduction report: running nonsmooth reproduce --quick (once per version) ...")
    ns.reproduce(out=out, quick=True, command="nonsmooth reproduce --quick (docs build)")
    stamp.write_text(json.dumps({"key": key}))


def setup(app):
    app.connect("builder-inited", generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
