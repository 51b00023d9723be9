"""The agreement report: ``report.md`` and a self-contained ``report.html`` (PNG figures embedded
as base64 data URIs), both written from the same records."""

from __future__ import annotations

import base64
import html
import json
import platform
import re
from pathlib import Path

from .core import AGREES, DIFFERS, FIGURES, NOT_STATED, FigureRecord
from .settings import rows as settings_rows

VERDICT_MARK = {AGREES: "agrees", DIFFERS: "DIFFERS", NOT_STATED: "not stated"}
VERDICT_COLOR = {AGREES: "#1a7f37", DIFFERS: "#cf222e", NOT_STATED: "#6e7781"}
#: version of the layout of ``summary.json`` (a folder with another layout starts afresh)
SUMMARY_FORMAT = 2


def gaps(evidence: dict, quick_ids: list[str]) -> list[tuple[str, str, list[str]]]:
    """(title, what the paper says / what we chose, evidence lines computed by the figures);
    ``quick_ids``: the figures computed in --quick mode."""
    from .figures._common import BASIN_WINDOW, IC, JUST_AFTER
    ev = lambda key: list(evidence.get(key, []))  # noqa: E731
    return [
        ("Eqs. 13a/13b are not the convex combinations of eqs. 12a/12b",
         "Eq. 12 interpolates the whole vector field linearly (quadratic support force in X, no "
         "memory); eq. 13a interpolates the spring force in X and ramps the support damping from "
         "the entry velocity X'_a (a discrete memory), eq. 13b interpolates the support force "
         "linearly in h_beta. They agree on the q = 1 edges but not on the Sigma_alpha/Sigma_beta "
         "border. We use eq. 13 (what the paper integrated) by default; `method=\"smooth_eq12\"` "
         "selects eq. 12.", ev("eq12")),
        ("The eta values used differ from the stated reference",
         "The text fixes eta_hat = eta g = 1e-5 'for all simulations', yet uses eta = 2.5e-6 "
         "(Table 2, Figs. 5-8), 6.25e-6 (Table 3, Figs. 9-10) and 5e-6 (Table 4, Figs. 11-12); "
         "g is never given, so eta_hat cannot be converted. We use the per-figure values.",
         ev("eta")),
        ("Table 4 column labels",
         "Table 4 prints 'xi' twice; we read the second column as xi_s = 0.60 (as in Table 3).",
         ev("table4")),
        ("Table 2 does not give omega_s",
         "Fig. 5 varies omega_s without listing values; we use omega_s = 1, 3.16, 10, 31.6, 100. "
         "Figs. 6-8 state omega_s (3.16, 7.07).", []),
        ("Initial conditions, section phase, transients and plotting windows",
         f"Never stated. We start every single trajectory at (X, V) = {IC} at t = 0 (forcing "
         "phase 0); Poincaré sections are taken at t = kT (forcing phase 0); resonance curves "
         "and bifurcation diagrams sweep up and down, each value starting from the state left by "
         "the previous one (the first from (0, 0)); basins use initial conditions at phase 0 on "
         f"X0 in {BASIN_WINDOW[0]}, V0 in {BASIN_WINDOW[1]}; chaos 'just after' grazing means "
         f"within {JUST_AFTER:.0%} of the swept range. Transients and grid sizes are listed "
         "per figure" + (f" ({', '.join(quick_ids)} from a --quick run: coarser grids, shorter "
                         "transients)." if quick_ids else "."), []),
        ("Fig. 7 colours and direction of the basin change",
         "The text calls the light basin 'without contact', then the non-impact attractor "
         "'dark' and the impact basin 'light'. We classify attractors by contact (max X >= 1 and "
         "a visit to the contact regions), not by colour; we read 'the light attractor increases "
         "its size' with the paper's definition (light = no contact) and test the sentence about "
         "omega_b and omega_c as written, against the resonance branches of Fig. 6a.", ev("fig7")),
        ("Tolerance and chaos criterion",
         "The paper gives rtol 1e-8 only; we use rtol = 1e-8, atol = 1e-10. 'Chaotic' is taken to "
         "mean that no period <= 64 repeats on the Poincaré section within 1e3 x the integration "
         "tolerance (period 0; quasi-periodic motion would also give 0). The experimental "
         "confirmation [13] of Fig. 4 cannot be checked here.", []),
    ]


def _rel(path: Path, out: Path) -> str:
    try:
        return str(Path(path).relative_to(out))
    except ValueError:
        return str(path)


def _summary_rows(records):
    for r in records:
        c = r.counts()
        status = "FAILED" if r.error else ("differs" if c[DIFFERS] else "agrees")
        yield r, c, status


def runs_of(records) -> list[tuple[dict, list[str]]]:
    """The runs that computed the figures shown, oldest first, each with its figure ids."""
    runs: dict = {}
    for r in records:
        key = (r.run["date"], r.run["command"])
        runs.setdefault(key, (r.run, []))[1].append(r.id)
    return [runs[k] for k in sorted(runs)]


def _mode(run: dict) -> str:
    return "quick" if run["quick"] else "full"


def header_lines(records) -> list[str]:
    """Which run computed which figures (command, settings, date): plain-text lines."""
    runs = runs_of(records)
    modes = sorted({_mode(run) for run, _ in runs})
    if len(modes) == 1:
        mode = modes[0] + (" (coarser grids, shorter transients)" if modes == ["quick"] else "")
    else:
        mode = "mixed: " + "; ".join(
            f"{m}: {', '.join(i for run, ids in runs for i in ids if _mode(run) == m)}"
            for m in modes)
    lines = [f"Mode: {mode}."]
    if len(runs) > 1:
        lines.append(f"{len(runs)} runs into this folder computed the figures below (a later "
                     "run replaces the figures it re-ran):")
    for run, ids in runs:
        lines.append(f"Run {run['date']}: `{run['command']}` ({_mode(run)}; "
                     f"{run['seconds']:.1f} s; {run['workers']} worker thread(s); nonsmooth "
                     f"{run['version']}; {run['platform']}): {', '.join(ids)}")
    return lines


def evidence_of(records) -> dict:
    """Gap evidence of all figures shown, by topic, in paper order."""
    ev: dict = {}
    for r in records:
        for key, text in r.gaps:
            ev.setdefault(key, []).append(text)
    return ev


def _computed_by(r) -> str:
    return f"{_mode(r.run)} run of {r.run['date']}"


def markdown(records: list[FigureRecord], out: Path) -> str:
    evidence = evidence_of(records)
    quick_ids = [r.id for r in records if r.run["quick"]]
    L = ["# Reproduction of 'Nonlinear dynamics and chaos in systems with discontinuous support'",
         ""]
    L += [f"{line}  " for line in header_lines(records)]
    L += ["",
          "Every verdict below is computed from the data of the run named for the figure: "
          "*agrees* / *differs* compare a measured quantity with the paper's statement by the "
          "criterion given in the row; *not stated* gives a measurement the paper does not make "
          "a claim about.",
          "", "## Summary", "",
          "| figure | claim of the paper | agrees | differs | not stated | time [s] | run "
          "| status |", "|---|---|---:|---:|---:|---:|---|---|"]
    for r, c, status in _summary_rows(records):
        L.append(f"| [{r.id}](#{r.id}) | {FIGURES[r.id].claim} | {c[AGREES]} | {c[DIFFERS]} | "
                 f"{c[NOT_STATED]} | {r.seconds:.1f} | {_computed_by(r)} | {status} |")
    tot = {v: sum(r.counts()[v] for r in records) for v in (AGREES, DIFFERS, NOT_STATED)}
    nfail = sum(1 for r in records if r.error)
    L += ["", f"**Totals:** {tot[AGREES]} agree, {tot[DIFFERS]} differ, {tot[NOT_STATED]} not "
              f"stated; {nfail} figure(s) failed.", ""]
    for r in records:
        L += [f"## {r.id}", "", f"**{r.title}.** Paper: {FIGURES[r.id].claim}.", ""]
        if r.error:
            L += [f"**FAILED** after {r.seconds:.1f} s: `{r.error}`", ""]
            if r.traceback:
                L += ["```", r.traceback.strip(), "```", ""]
        if r.params:
            L.append("Parameters: " + ", ".join(f"{k} = {v}" for k, v in r.params.items()) + "  ")
        if r.method:
            L.append(f"Method: {r.method}  ")
        if r.settings:
            L.append("Settings: " + "; ".join(f"{k}: {v}" for k, v in r.settings.items()) + "  ")
        L.append(f"Computed by the {_computed_by(r)} in {r.seconds:.1f} s")
        L.append("")
        if r.checks:
            L += ["| paper | ours | verdict |", "|---|---|---|"]
            for c in r.checks:
                m = c.measured.replace("|", "/")
                if c.evidence:
                    m += f"<br>*evidence:* {c.evidence.replace('|', '/')}"
                L.append(f"| {c.claim.replace('|', '/')} | {m} | **{VERDICT_MARK[c.verdict]}** |")
            L.append("")
        for n in r.notes:
            L += [f"- {n}"]
        if r.notes:
            L.append("")
        pngs = [f for f in r.files if str(f).endswith(".png")]
        for f in pngs:
            L += [f"![{r.id}]({_rel(f, out)})", ""]
        files = ", ".join(f"`{_rel(f, out)}`" for f in r.files)
        if files:
            L += [f"Files: {files}", ""]
    L += ["## Where the paper is silent or inconsistent", ""]
    for title, text, lines in gaps(evidence, quick_ids):
        L += [f"### {title}", "", text, ""]
        for line in lines:
            L.append(f"- Computed: {line}")
        if lines:
            L.append("")
    L += ["## Settings of a full and a --quick run", "", "| figures | setting | full | quick |",
          "|---|---|---:|---:|"]
    L += [f"| {g} | {k} | {full} | {quick} |" for g, k, full, quick in settings_rows()]
    return "\n".join(L) + "\n"


def _img(path: Path) -> str:
    data = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    return f'<img alt="{html.escape(Path(path).name)}" src="data:image/png;base64,{data}">'


def html_page(records: list[FigureRecord], out: Path) -> str:
    e = html.escape
    evidence = evidence_of(records)
    quick_ids = [r.id for r in records if r.run["quick"]]
    H = ["<!DOCTYPE html><html><head><meta charset='utf-8'>",
         "<title>nonsmooth: reproduction report</title><style>",
         "body{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto;padding:0 1em;"
         "line-height:1.4}table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;"
         "padding:4px 8px;vertical-align:top;font-size:14px}th{background:#f3f3f3}"
         "img{max-width:100%;border:1px solid #ddd;margin:.5em 0}.ev{color:#555;font-size:12px}"
         "pre{background:#f6f8fa;padding:8px;overflow:auto;font-size:12px}.meta{color:#444}",
         "</style></head><body>",
         "<h1>Reproduction of &lsquo;Nonlinear dynamics and chaos in systems with discontinuous "
         "support&rsquo;</h1>",
         "<p class='meta'>" + "<br>".join(re.sub(r"`([^`]*)`", r"<code>\1</code>", e(line))
                                          for line in header_lines(records)) + "</p>",
         "<p>Every verdict is computed from the data of the run named for the figure, by the "
         "criterion given in the row.</p>",
         "<h2>Summary</h2><table><tr><th>figure</th><th>claim of the paper</th><th>agrees</th>"
         "<th>differs</th><th>not stated</th><th>time [s]</th><th>run</th><th>status</th></tr>"]
    for r, c, status in _summary_rows(records):
        col = VERDICT_COLOR[DIFFERS] if status != "agrees" else VERDICT_COLOR[AGREES]
        H.append(f"<tr><td><a href='#{r.id}'>{r.id}</a></td><td>{e(FIGURES[r.id].claim)}</td>"
                 f"<td>{c[AGREES]}</td><td>{c[DIFFERS]}</td><td>{c[NOT_STATED]}</td>"
                 f"<td>{r.seconds:.1f}</td><td>{e(_computed_by(r))}</td>"
                 f"<td style='color:{col}'><b>{status}</b></td></tr>")
    H.append("</table>")
    for r in records:
        H.append(f"<h2 id='{r.id}'>{r.id}: {e(r.title)}</h2><p><b>Paper:</b> "
                 f"{e(FIGURES[r.id].claim)}.</p>")
        if r.error:
            H.append(f"<p style='color:{VERDICT_COLOR[DIFFERS]}'><b>FAILED</b> after "
                     f"{r.seconds:.1f} s: <code>{e(r.error)}</code></p>"
                     + (f"<pre>{e(r.traceback)}</pre>" if r.traceback else ""))
        items = []
        if r.params:
            items.append("<b>Parameters:</b> " + e(", ".join(f"{k} = {v}" for k, v in r.params.items())))
        if r.method:
            items.append(f"<b>Method:</b> {e(r.method)}")
        if r.settings:
            items.append("<b>Settings:</b> " + e("; ".join(f"{k}: {v}" for k, v in r.settings.items())))
        items.append(f"<b>Computed by the</b> {e(_computed_by(r))} in {r.seconds:.1f} s")
        H.append("<p>" + "<br>".join(items) + "</p>")
        if r.checks:
            H.append("<table><tr><th>paper</th><th>ours</th><th>verdict</th></tr>")
            for c in r.checks:
                ev = f"<div class='ev'>evidence: {e(c.evidence)}</div>" if c.evidence else ""
                H.append(f"<tr><td>{e(c.claim)}</td><td>{e(c.measured)}{ev}</td>"
                         f"<td style='color:{VERDICT_COLOR[c.verdict]}'><b>"
                         f"{VERDICT_MARK[c.verdict]}</b></td></tr>")
            H.append("</table>")
        if r.notes:
            H.append("<ul>" + "".join(f"<li>{e(n)}</li>" for n in r.notes) + "</ul>")
        for f in r.files:
            if str(f).endswith(".png") and Path(f).is_file():
                H.append(_img(f))
        if r.files:
            H.append("<p class='meta'>Files: " + ", ".join(
                f"<code>{e(_rel(f, out))}</code>" for f in r.files) + "</p>")
    H.append("<h2>Where the paper is silent or inconsistent</h2>")
    for title, text, lines in gaps(evidence, quick_ids):
        H.append(f"<h3>{e(title)}</h3><p>{e(text)}</p>")
        if lines:
            H.append("<ul>" + "".join(f"<li>Computed: {e(x)}</li>" for x in lines) + "</ul>")
    H.append("<h2>Settings of a full and a --quick run</h2><table><tr><th>figures</th>"
             "<th>setting</th><th>full</th><th>quick</th></tr>")
    H += [f"<tr><td>{e(g)}</td><td>{e(k)}</td><td>{full}</td><td>{quick}</td></tr>"
          for g, k, full, quick in settings_rows()]
    H.append("</table></body></html>")
    return "\n".join(H) + "\n"


def write_reports(records: list[FigureRecord], out: Path) -> None:
    """Write ``report.md``, ``report.html`` and ``summary.json`` for ``records`` (every figure
    the folder holds, in paper order), each file atomically."""
    from ..io import write_file
    write_file(out / "report.md", markdown(records, out), "out")
    write_file(out / "report.html", html_page(records, out), "out")
    summary = {"format": SUMMARY_FORMAT, "figures": [r.to_dict() for r in records],
               "gap_evidence": evidence_of(records)}
    write_file(out / "summary.json", json.dumps(summary, indent=1), "out")


def load_summary(out: Path) -> dict[str, FigureRecord]:
    """The figure records of an earlier run into ``out`` (``summary.json``), by id; empty when
    there is none or it cannot be read (the report then starts afresh)."""
    try:
        summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
        if summary.get("format") != SUMMARY_FORMAT:
            return {}
        recs = [FigureRecord.from_dict(d, out) for d in summary["figures"]]
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return {}
    return {r.id: r for r in recs if r.id in FIGURES}


def platform_text() -> str:
    import os
    return f"Python {platform.python_version()}, {platform.machine()}, {os.cpu_count()} CPU(s)"
