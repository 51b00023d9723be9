"""The documentation cannot go stale: every ```python block of its pages runs (each page in
order, in one namespace, in a fresh folder), and the API reference lists every public name.
The gallery and the tutorial are executed by the docs build itself (sphinx-gallery)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[1] / "docs"
SKIP = {"_build", "_generated", "generated", "auto_gallery", "auto_tutorials"}
PAGES = sorted(p for p in DOCS.rglob("*.md") if not SKIP & set(p.relative_to(DOCS).parts))
BLOCK = re.compile(r"^```python\n(.*?)^```", re.S | re.M)


def python_blocks(page: Path) -> list[str]:
    return BLOCK.findall(page.read_text())


def test_the_pages_are_found():
    names = {p.relative_to(DOCS).as_posix() for p in PAGES}
    assert {"index.md", "getting_started.md", "api.md", "guide/analyses.md"} <= names
    assert sum(len(python_blocks(p)) for p in PAGES) >= 20


@pytest.mark.parametrize("page", [p for p in PAGES if python_blocks(p)],
                         ids=lambda p: p.relative_to(DOCS).as_posix())
def test_the_code_of_each_page_runs(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    scope = {"__name__": "docs_page"}
    for k, code in enumerate(python_blocks(page)):
        try:
            exec(compile(code, f"{page.name}[block {k}]", "exec"), scope)
        except Exception as exc:  # noqa: BLE001 - name the page and block
            raise AssertionError(f"{page.relative_to(DOCS)}, python block {k}: "
                                 f"{type(exc).__name__}: {exc}") from exc


def test_the_api_reference_lists_every_public_name():
    import nonsmooth as ns
    import nonsmooth.explore
    import nonsmooth.models

    text = (DOCS / "api.md").read_text()
    listed = set(re.findall(r"^   ([A-Za-z_][A-Za-z0-9_]*)$", text, re.M))
    listed |= set(re.findall(r"`nonsmooth\.(?:plot\.)?([A-Za-z_]+)`", text))
    missing = [f"nonsmooth.{n}" for n in ns.__all__ if n not in listed]
    missing += [f"nonsmooth.plot.{n}" for n in ns.plot.__all__ if n not in listed]
    missing += [f"nonsmooth.models.{n}" for n in ("Model", "Method", "Param", "ModelParams",
                                                  "param_index") if n not in listed]
    missing += [f"nonsmooth.explore.{n}" for n in nonsmooth.explore.__all__ if n not in listed]
    assert not missing, f"docs/api.md does not list {missing}"
