"""`nonsmooth explore`: what it computes (without a page), its command's errors, and the page
itself in a real browser (headless Chromium from the system packages, driven by Selenium; those
tests skip with the reason when no Chromium is installed).

No test waits a fixed time: each waits for what it observes (a line of output, a text in the
page, a changed data source) and stops only at a safety limit.
"""

from __future__ import annotations

import math
import os
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth.explore import compute
from nonsmooth.explore.page import export_text, slice_range, slider_range, slider_scale

LIMIT = 300.0  # safety limit of every wait (s): never reached when things work
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMEDRIVER = shutil.which("chromedriver")


def wait_for(predicate, what: str, limit: float = LIMIT):
    """Poll ``predicate`` until it returns something truthy (returned)."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < limit:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


# ---- what the page computes --------------------------------------------------------------------
def test_slider_and_slice_ranges_are_allowed_by_the_model():
    m = ns.model("support")
    for name, v in (("eta", 1e-5), ("omega", 0.91), ("F0", 0.3), ("xi", 0.05)):
        prm = m.param(name)
        lo, hi = slider_range(prm, v)
        assert lo <= v <= hi or name == "eta"   # eta: the field sets what the slider can't
        prm.check(lo), prm.check(hi)      # open ends moved in: both ends allowed
    assert slider_range(m.param("eta"), 1e-5) == (0.5 / 400, 0.5 - 0.5 / 400)
    # ... so eta's slider moves in log10 (a decade below the value up to the range's end)
    lo, hi, log = slider_scale(m.param("eta"), 2.5e-6)
    assert log and lo == pytest.approx(math.log10(2.5e-7)) and 10 ** hi == pytest.approx(
        0.5 - 0.5 / 400)
    assert slider_scale(m.param("omega"), 0.91)[2] is False
    # the slice's default range passes the cross-field rules too: support needs xi_s = 0
    # where omega_s = 0, stick_slip mu_s >= mu_k
    values = ns.preset("table3").as_dict()
    lo, hi = slice_range(m, values, "omega_s")
    assert lo < values["omega_s"] < hi
    m.validate({**values, "omega_s": lo}), m.validate({**values, "omega_s": hi})
    ss = ns.model("stick_slip")
    sv = ss.preset("stribeck").as_dict()
    lo, hi = slice_range(ss, sv, "mu_s")
    assert lo < sv["mu_s"] < hi
    ss.validate({**sv, "mu_s": lo})


def test_current_orbit_matches_poincare_and_reports_failures():
    p = ns.preset("table3").replace(omega=0.91)
    orb = compute.current_orbit(p, "exact", [0.0, 0.0])
    sec = ns.poincare(p, record=compute.VIEW_RECORD, transient=compute.VIEW_TRANSIENT,
                      method="exact")
    assert orb.status == "ok" and orb.period == int(sec.period) == 3
    np.testing.assert_allclose(orb.section["X"], sec.X.values, rtol=0, atol=1e-12)
    assert orb.summary().startswith("period 3, λ1 = ")
    assert len(orb.t) == len(orb.mode) == len(orb.u["V"]) > 0
    # an unforced model: its time response only, said in one line
    free = compute.current_orbit(ns.model("stick_slip").params(), "exact", [0.0, 0.0])
    assert free.status == "ok" and free.period is None and len(free.t) > 0
    assert "no stroboscopic section" in free.summary()
    # a start the model does not admit: a status, never an exception
    bad = compute.current_orbit(ns.model("bouncing_ball").params(), "exact", [-1.0, 0.0])
    assert bad.status.startswith("failed: ") and "\n" not in bad.status


def test_the_orbit_is_drawn_before_its_lambda1():
    p = ns.preset("table3").replace(omega=0.92)
    first, second = compute.orbit_stages(p, "exact", [0.0, 0.0])
    assert first.lambda1_pending and "λ1: computing" in first.summary()
    assert math.isnan(first.lambda1)
    full = compute.current_orbit(p, "exact", [0.0, 0.0])
    assert not second.lambda1_pending and second.lambda1 == full.lambda1 > 0
    np.testing.assert_array_equal(first.section["X"], second.section["X"])
    assert second.motion == "chaotic"


def test_orbit_slice_equals_one_sweep_and_stops_when_superseded():
    p = ns.preset("table3")
    values = np.linspace(0.85, 0.95, 12)
    parts = list(compute.orbit_slice(p, "exact", "omega", values, [0.0, 0.0], chunk=5,
                                     transient=100, record=20))
    with pytest.raises(ns.ParameterError, match="orbit diagram"):
        next(compute.orbit_slice(ns.model("stick_slip").params(), "exact", "v_belt",
                                 values, [0.0, 0.0]))
    assert [len(v) for v, _, _ in parts] == [5, 5, 2]
    whole = ns.bifurcation_diagram(p, "omega", values, sweep="up", transient=100, record=20,
                                   method="exact", lyapunov=False)
    got = np.concatenate([pts for _, pts, _ in parts])
    # chunks continue from the last section point: the same sweep up to the transient's
    # settling (periodic points agree to the section's tolerance)
    per = whole.period.isel(sweep=0).values
    same = per > 0
    assert same.sum() >= 6
    np.testing.assert_allclose(np.sort(got[same], axis=1),
                               np.sort(whole.X.isel(sweep=0).values[same], axis=1), atol=1e-6)
    # several degrees of freedom: every component carried from chunk to chunk, as one sweep
    q = ns.model("impact_2dof").preset("period_one")
    om = q.omega * np.linspace(0.97, 1.03, 6)
    u0 = [0.1, 0.0, 0.3, 0.0]
    chunks = np.concatenate([pts for _, pts, _ in compute.orbit_slice(
        q, "exact", "omega", om, u0, chunk=2, transient=60, record=5)])
    one = ns.bifurcation_diagram(q, "omega", om, sweep="up", transient=60, record=5,
                                 method="exact", lyapunov=False, u0=u0)
    np.testing.assert_allclose(chunks, one.X.isel(sweep=0).values, rtol=0, atol=1e-9)
    calls = []
    gen = compute.orbit_slice(p, "exact", "omega", values, [0.0, 0.0], chunk=5, transient=50,
                              record=10, alive=lambda: not calls)
    next(gen)
    calls.append(1)                      # a newer request arrived
    with pytest.raises(compute.Cancelled):
        next(gen)


def test_latest_worker_computes_only_the_newest_request():
    started, release = threading.Event(), threading.Event()
    delivered = []

    def work(x, alive):
        if x == 0:
            started.set()
            release.wait(LIMIT)
        return x

    w = compute.LatestWorker(work, lambda g, v: delivered.append(v))
    w.submit(0)
    started.wait(LIMIT)
    for x in (1, 2, 3):                 # 1 and 2 superseded before they start
        w.submit(x)
    release.set()
    wait_for(lambda: 3 in delivered, "the newest result")
    w.stop()
    assert delivered == [3]             # 0 finished after being superseded: dropped


def test_export_text_is_a_command_and_a_snippet_that_run(tmp_path):
    m = ns.model("impact")
    values = m.params(r=0.7).as_dict()
    text = export_text("impact", m, values, "exact", [0.1, 0.0])
    line, _, snippet = text.partition("\n\n")
    assert line.startswith("nonsmooth poincare ") and "--set r=0.7" in line
    args = shlex.split(line)
    args[args.index("--record") + 1] = "20"
    args[args.index("--transient") + 1] = "20"
    out = subprocess.run([sys.executable, "-m", "nonsmooth", *args[1:]], cwd=tmp_path,
                         capture_output=True, text=True, timeout=LIMIT)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "explore.nc").is_file()
    ds = ns.io.load_dataset(tmp_path / "explore.nc")
    assert ds.attrs["param_r"] == 0.7 and ds.attrs["method"] == "exact"
    scope = {}
    exec(snippet.replace("record=200, transient=200", "record=20, transient=20"), scope)
    assert scope["ds"].attrs["param_r"] == 0.7


@pytest.mark.parametrize("args, field", [
    (["--model", "nope"], "model"),
    (["--set", "omega=-1"], "omega"),
    (["--param", "nope"], "nope"),
    (["--show", "X,Q"], "show"),
    (["--port", "70000"], "port"),
])
def test_explore_bad_input_is_one_line_and_exit_2(args, field):
    out = subprocess.run([sys.executable, "-m", "nonsmooth", "explore", "--no-browser", *args],
                         capture_output=True, text=True, timeout=LIMIT)
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and field in lines[0] and "Traceback" not in out.stderr


def test_a_port_in_use_is_one_line_and_exit_2():
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        out = subprocess.run([sys.executable, "-m", "nonsmooth", "explore", "--no-browser",
                              "--port", str(port)], capture_output=True, text=True, timeout=LIMIT)
    assert out.returncode == 2
    assert out.stderr.strip() == f"error: port: cannot listen on 127.0.0.1:{port} (in use)"


# ---- the page in a real browser -----------------------------------------------------------------
class Server:
    """``nonsmooth explore --no-browser`` in a subprocess; its URL from its first line."""

    def __init__(self, *args):
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        self.proc = subprocess.Popen([sys.executable, "-m", "nonsmooth", "explore",
                                      "--no-browser", *args], stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True, env=env)
        self.lines = []
        threading.Thread(target=self._read, daemon=True).start()
        line = wait_for(lambda: next((x for x in self.lines if "http://" in x), None),
                        "the server's address")
        self.url = line.split()[2]

    def _read(self):
        for line in self.proc.stdout:
            self.lines.append(line.rstrip())

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGINT)
            try:
                return self.proc.wait(timeout=LIMIT)
            finally:
                if self.proc.poll() is None:
                    self.proc.kill()
        return self.proc.returncode


needs_browser = pytest.mark.skipif(
    CHROMIUM is None or CHROMEDRIVER is None,
    reason="no Chromium: install the system packages (apt-get install chromium chromium-driver)")


@pytest.fixture(scope="module")
def browser():
    pytest.importorskip("selenium", reason="selenium is not installed (pip install '.[test]')")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
              "--window-size=1500,1300"):
        opts.add_argument(a)
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=opts)
    yield driver
    driver.quit()


@pytest.fixture(scope="module")
def page(browser):
    server = Server("--preset", "table3", "--method", "exact", "--set", "omega=0.91")
    browser.get(server.url)
    yield Page(browser, server)
    server.stop()


class Page:
    """The explore page as its Bokeh models (by name) and their views (for real input)."""

    def __init__(self, driver, server):
        self.d, self.server = driver, server
        wait_for(lambda: self.js("return window.Bokeh && Bokeh.documents.length > 0 && "
                                 "Bokeh.documents[0].get_model_by_name('status') !== null"),
                 "the page's document")

    def js(self, code, *args):
        return self.d.execute_script(code, *args)

    def prop(self, name, attr):
        return self.js(f"return Bokeh.documents[0].get_model_by_name({name!r}).{attr}")

    def data(self, source, column):
        return self.js(f"return Array.from(Bokeh.documents[0].get_model_by_name({source!r})"
                       f".data[{column!r}])")

    def element(self, name, inner=None):
        """The DOM element of a model's view (its ``inner`` element, e.g. 'input')."""
        return self.js(
            "const m = Bokeh.documents[0].get_model_by_name(arguments[0]);"
            "const v = Object.values(Bokeh.index)[0].owner.get_one(m);"
            "return arguments[1] ? v.shadow_el.querySelector(arguments[1]) : v.el;",
            name, inner)

    def type_into(self, name, text):
        from selenium.webdriver.common.keys import Keys

        el = self.element(name, "input")       # select what is there, type over it, Enter
        self.js("arguments[0].focus(); arguments[0].select();", el)
        from selenium.webdriver.common.action_chains import ActionChains

        ActionChains(self.d).send_keys(text + Keys.ENTER).perform()

    def status(self):
        return self.prop("status", "text")

    def settled(self):
        s = self.status()
        return s if s and "computing" not in s else None


@needs_browser
def test_the_page_loads_and_shows_the_orbit(page):
    status = wait_for(page.settled, "the first orbit")
    assert status.startswith("period 3"), status          # table 3, omega = 0.91: period 3
    assert page.prop("param_omega", "value") == "0.91"
    assert len(page.data("section_source", "a")) == compute.VIEW_RECORD
    assert len(page.data("time_source", "t")) > 100
    assert sorted(page.prop("method", "options")) == ["exact", "smooth", "smooth_closed_form",
                                                      "smooth_eq12"]
    assert "Γ" in page.prop("modes", "text") or "Gamma" in page.prop("modes", "text")
    eta = float(page.prop("param_eta", "value"))  # a log slider: eta spans decades
    assert page.prop("slider_eta", "value") == pytest.approx(math.log10(eta))


@needs_browser
def test_moving_a_parameter_changes_the_plotted_data(page):
    wait_for(page.settled, "the first orbit")
    before = page.data("section_source", "a")
    page.type_into("param_omega", "0.92")
    wait_for(lambda: page.data("section_source", "a") != before, "new section points")
    status = wait_for(page.settled, "the orbit at omega = 0.92")
    assert "no period" in status and "chaotic" in status, status
    after = page.data("section_source", "a")
    assert len(set(np.round(after, 6))) > 50              # chaotic: no repeating points
    assert page.prop("slider_omega", "value") == pytest.approx(0.92)


@needs_browser
def test_an_out_of_range_value_is_refused_by_its_field(page):
    status = wait_for(page.settled, "an orbit")
    page.type_into("param_eta", "-1")
    title = wait_for(lambda: "⚠" in page.prop("param_eta", "title") and
                     page.prop("param_eta", "title"), "the field's message")
    assert "eta" in title and "must satisfy" in title
    assert page.settled() == status                      # nothing was computed
    page.type_into("param_eta", "1e-05")
    wait_for(lambda: "⚠" not in page.prop("param_eta", "title"), "the field cleared")


@needs_browser
def test_the_orbit_diagram_completes_and_a_click_sets_the_parameter(page):
    text = wait_for(lambda: "(complete)" in (page.prop("slice_status", "text") or "") and
                    page.prop("slice_status", "text"), "the orbit-diagram slice")
    n = int(page.prop("slice_values", "value"))
    assert f"{n} of {n} values" in text
    values = np.array(page.data("slice_source", "value"))
    lo, hi = float(page.prop("slice_from", "value")), float(page.prop("slice_to", "value"))
    assert values.size >= n and values.min() == pytest.approx(lo) and values.max() == \
        pytest.approx(hi)
    from selenium.webdriver.common.action_chains import ActionChains

    before = float(page.prop("param_omega", "value"))
    fig = page.element("orbit_diagram")
    ActionChains(page.d).move_to_element_with_offset(fig, 150, 0).click().perform()
    new = wait_for(lambda: float(page.prop("param_omega", "value")) != before and
                   float(page.prop("param_omega", "value")), "the clicked parameter value")
    assert lo < new < hi and new > 0.5 * (lo + hi)        # right of the centre
    assert page.prop("slider_omega", "value") == pytest.approx(new)


@needs_browser
def test_a_click_in_the_phase_plane_sets_the_initial_condition(page):
    wait_for(page.settled, "an orbit")
    from selenium.webdriver.common.action_chains import ActionChains

    fig = page.element("phase_portrait")
    ActionChains(page.d).move_to_element_with_offset(fig, 40, -30).click().perform()
    x0 = wait_for(lambda: float(page.prop("u0_X", "value")) != 0.0 and
                  float(page.prop("u0_X", "value")), "the clicked initial condition")
    assert math.isfinite(x0) and math.isfinite(float(page.prop("u0_V", "value")))


@needs_browser
def test_export_gives_a_command_that_runs(page, tmp_path):
    wait_for(page.settled, "an orbit")
    page.element("export", "button").click()
    text = wait_for(lambda: page.prop("export_text", "value"), "the exported text")
    line = text.split("\n\n")[0]
    omega = page.prop("param_omega", "value")
    assert line.startswith("nonsmooth poincare ") and f"--set omega={omega}" in line
    args = shlex.split(line)
    args[args.index("--record") + 1] = "20"
    out = subprocess.run([sys.executable, "-m", "nonsmooth", *args[1:]], cwd=tmp_path,
                         capture_output=True, text=True, timeout=LIMIT)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "explore.nc").is_file() and (tmp_path / "explore.png").is_file()


@needs_browser
def test_a_model_that_fails_to_load_is_one_line_and_the_page_keeps_working(page):
    wait_for(page.settled, "an orbit")
    page.type_into("model", "no_such_model")
    msg = wait_for(lambda: page.prop("message", "text"), "the page's message")
    assert msg.startswith("model no_such_model: ") and "\n" not in msg
    assert page.prop("model", "value") == "support"
    page.type_into("model", "impact")
    wait_for(lambda: page.prop("model", "value") == "impact" and
             page.js("return Bokeh.documents[0].get_model_by_name('param_r') !== null"),
             "the impact model's fields")
    assert page.prop("message", "text") == ""
    wait_for(page.settled, "the impact orbit")
    # four state components: the slice carries all of them, the page shows X and V
    page.type_into("model", "impact_2dof")
    wait_for(lambda: page.js("return Bokeh.documents[0].get_model_by_name('u0_W') !== null"),
             "the 2-DOF model's fields")
    wait_for(lambda: "(complete)" in (page.prop("slice_status", "text") or ""),
             "the 2-DOF slice")
    assert wait_for(page.settled, "the 2-DOF orbit").startswith("period")
    # no forcing: the time response, and one line saying why there is no orbit diagram
    page.type_into("model", "stick_slip")
    wait_for(lambda: page.js("return Bokeh.documents[0].get_model_by_name('param_v_belt') "
                             "!== null"), "the friction model's fields")
    assert "no stroboscopic section" in wait_for(page.settled, "the self-excited orbit")
    assert page.prop("slice_status", "text").startswith("⚠ no orbit diagram: without forcing")
    assert len(page.data("time_source", "t")) > 100


@needs_browser
def test_ctrl_c_stops_the_server_cleanly():
    server = Server("--model", "impact")
    assert server.stop() == 0
    wait_for(lambda: any("stopped" in x for x in server.lines), "the last line")
    assert not any("Traceback" in x for x in server.lines)
