"""`nonsmooth reproduce`: the registry, computed verdicts, failure isolation, the report files.

The quick reproduction of every figure runs once per session (module fixture, ~1-2 min on two
cores); the other tests use single cheap figures.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from nonsmooth.cli import main
from nonsmooth.errors import ParameterError
from nonsmooth.reproduction import AGREES, DIFFERS, FIGURES, NOT_STATED, figure_ids, reproduce
from nonsmooth.reproduction.core import agree_if, figure, verdict_period

PAPER_FIGURES = ["fig3", "fig4", "fig5", "fig6a", "fig6b", "fig7a", "fig7b", "fig8", "fig9",
                 "fig10a", "fig10b", "fig11", "fig12a", "fig12b", "fig12c"]


@pytest.fixture(scope="module")
def quick_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce")
    records = reproduce(out, quick=True)
    return out, records


def test_registry_covers_every_figure_in_paper_order():
    assert list(FIGURES) == PAPER_FIGURES
    for spec in FIGURES.values():
        assert spec.claim and spec.title


def test_figure_ids_selection():
    assert figure_ids(None) == PAPER_FIGURES
    assert figure_ids("fig11,fig9") == ["fig9", "fig11"]  # paper order
    assert figure_ids("fig6") == ["fig6a", "fig6b"]
    assert figure_ids(["fig12", "fig3"]) == ["fig3", "fig12a", "fig12b", "fig12c"]
    with pytest.raises(ParameterError, match="fig99"):
        figure_ids("fig3,fig99")


def test_verdict_helpers():
    assert agree_if(True) == AGREES and agree_if(False) == DIFFERS
    assert agree_if(float("nan") > 0) == DIFFERS
    assert verdict_period(3, 3) == AGREES
    assert verdict_period(0, 3) == DIFFERS
    assert verdict_period(2, None) == DIFFERS


def test_failing_figure_is_recorded_and_the_run_goes_on(tmp_path, monkeypatch):
    monkeypatch.setitem(FIGURES, "figbroken", None)  # placeholder, replaced by the decorator

    @figure("figbroken", "a figure whose analysis is missing", "nothing")
    def broken(ctx, rec):
        raise ImportError("no module named nonsmooth.analysis.missing")

    records = reproduce(tmp_path, only="figbroken,fig12c", quick=True)
    by_id = {r.id: r for r in records}
    assert "ImportError" in by_id["figbroken"].error
    assert by_id["fig12c"].ok
    md = (tmp_path / "report.md").read_text()
    assert "FAILED" in md and "missing" in md
    assert (tmp_path / "fig12c.png").is_file() and (tmp_path / "fig12c.nc").is_file()


def test_verdicts_are_computed_from_the_data(tmp_path, monkeypatch):
    """Replace the detected period of Fig. 12a's point: the verdict must follow the data."""
    import nonsmooth.analysis.poincare as pc
    real = pc.poincare

    def fake(params, **kw):
        ds = real(params, **kw)
        ds["period"] = 5
        return ds

    monkeypatch.setattr(pc, "poincare", fake)
    (rec,) = reproduce(tmp_path, only="fig12a", quick=True)
    first = rec.checks[0]
    assert first.verdict == DIFFERS and "period 5" in first.measured
    assert first.evidence  # a differing period gets computed evidence (ICs, transient, exact)
    monkeypatch.setattr(pc, "poincare", real)
    (rec,) = reproduce(tmp_path, only="fig12a", quick=True)
    assert rec.checks[0].verdict == AGREES


def test_quick_run_writes_every_figure_and_the_report(quick_run):
    out, records = quick_run
    assert [r.id for r in records] == PAPER_FIGURES
    failed = {r.id: r.error for r in records if r.error}
    assert not failed, failed
    for r in records:
        assert (out / f"{r.id}.png").is_file(), r.id
        assert (out / f"{r.id}.nc").is_file(), r.id
        assert r.checks, f"{r.id}: no verdict computed"
        assert all(c.verdict in (AGREES, DIFFERS, NOT_STATED) for c in r.checks)
        assert any(c.verdict != NOT_STATED for c in r.checks), f"{r.id}: no claim checked"
        assert r.seconds > 0
    md = (out / "report.md").read_text()
    html = (out / "report.html").read_text()
    assert "Where the paper is silent or inconsistent" in md
    assert html.count("data:image/png;base64,") >= len(PAPER_FIGURES)
    assert "<img" in html and 'src="fig' not in html  # self-contained
    summary = json.loads((out / "summary.json").read_text())
    assert [f["id"] for f in summary["figures"]] == PAPER_FIGURES


def test_quick_run_agrees_with_the_robust_claims(quick_run):
    """Claims that hold with any reasonable settings (not a hand-written expectation of every
    verdict: differences with the paper are allowed and explained in the report)."""
    _, records = quick_run
    by_id = {r.id: r for r in records}
    assert by_id["fig3"].checks[0].verdict == AGREES  # all four regions visited
    assert all(c.verdict == AGREES for c in by_id["fig5"].checks if "succeeds" in c.claim)
    for fid in ("fig10a", "fig12a", "fig12c"):
        assert by_id[fid].checks[0].verdict == AGREES, (fid, by_id[fid].checks[0])


def test_netcdf_files_carry_provenance(quick_run):
    import xarray as xr
    out, _ = quick_run
    with xr.open_dataset(out / "fig10a.nc", engine="h5netcdf") as ds:
        assert ds.attrs["param_omega"] == pytest.approx(0.91)
        assert "nonsmooth_version" in ds.attrs and ds.attrs["method"] == "smooth"
        assert np.isfinite(ds.X.values).all()


def test_cli_unknown_figure_is_one_line_error(capsys, tmp_path):
    with pytest.raises(SystemExit) as exc:
        main(["reproduce", "--out", str(tmp_path), "--only", "fig3,nope"])
    assert exc.value.code != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "nope" in err


def test_cli_runs_one_figure(capsys, tmp_path):
    with pytest.raises(SystemExit) as exc:
        main(["reproduce", "--out", str(tmp_path), "--only", "fig12c", "--quick", "--workers", "1"])
    assert exc.value.code in (0, None)
    out = capsys.readouterr().out
    assert "report.md" in out
    assert (tmp_path / "report.html").is_file() and (tmp_path / "fig12c.png").is_file()
    for name in ("report.md", "report.html", "summary.json"):  # every file it writes, named
        assert f"wrote {tmp_path / name}" in out and (tmp_path / name).is_file()
