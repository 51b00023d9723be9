"""The explore page: a Bokeh document with a field and a slider per parameter, the method, the
initial condition, and three linked panels (time response by mode, phase portrait with the
section points, an orbit-diagram slice that fills in progressively). Computations run in
background threads (``compute.LatestWorker``): a newer request supersedes an older one.
"""

from __future__ import annotations

import html
import math
import shlex
import threading
from functools import partial

import numpy as np

from ..errors import NonsmoothError, ParameterError
from . import compute

#: Steps of a slider; the text field beside it takes any value in range.
SLIDER_STEPS = 400
#: Default number of values of the orbit-diagram slice.
SLICE_VALUES = 200
#: Colour of each mode (as the figures of nonsmooth.plot).
MODE_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
               "#17becf")


def slider_range(prm, value: float) -> tuple[float, float]:
    """A slider's (start, end) for parameter ``prm`` around ``value``: the parameter's own
    bounds where finite (an open end moved in by one slider step, so that both ends are
    allowed), else a range around the value (up to twice a positive one)."""
    lo = prm.low if math.isfinite(prm.low) else None
    hi = prm.high if math.isfinite(prm.high) else None
    span = max(abs(value), 1.0)
    if lo is None:
        lo = value - span if value <= 0 or (hi is not None and hi <= 0) else 0.0
    if hi is None:
        hi = max(2.0 * value, lo + span) if value > 0 else value + span
    if hi - lo > 20 * span and value > 0 and lo >= 0:      # e.g. 0 < omega_s < inf
        hi = max(4.0 * value, lo + span)
    step = (hi - lo) / SLIDER_STEPS
    if prm.low_open and lo == prm.low:
        lo += step
    if prm.high_open and hi == prm.high:
        hi -= step
    return float(lo), float(hi)


def slider_scale(prm, value: float) -> tuple[float, float, bool]:
    """(start, end, log) of a parameter's slider: ``slider_range``, or, for a positive value
    below that range's start (a parameter that spans decades, e.g. the band eta = 2.5e-6 of
    0 < eta < 0.5), a slider in log10 from a decade below the value to the range's end."""
    lo, hi = slider_range(prm, value)
    if value > 0 and hi > 0 and value < lo:
        return math.log10(value) - 1.0, math.log10(hi), True
    return lo, hi, False


def slice_range(model, values: dict, name: str) -> tuple[float, float]:
    """The default range of the orbit-diagram slice over ``name``: +-20 % around its value
    (the slider's range for a value of 0), narrowed until both ends pass the model's checks
    (its parameter ranges and cross-field rules)."""
    prm = model.param(name)
    v = values[name]
    lo, hi = (0.8 * v, 1.2 * v) if v > 0 else (1.2 * v, 0.8 * v) if v < 0 else \
        slider_range(prm, v)
    for _ in range(30):
        if _allowed(model, values, name, lo) and _allowed(model, values, name, hi):
            return lo, hi
        lo, hi = v + 0.5 * (lo - v), v + 0.5 * (hi - v)
    return v, v


def _allowed(model, values: dict, name: str, x: float) -> bool:
    try:
        model.validate({**values, name: x})
    except ParameterError:
        return False
    return True


def _one_line(exc) -> str:
    """An exception's first line, escaped for a Div's HTML."""
    return html.escape(compute.first_line(exc))


def _label(prm) -> str:
    """A parameter field's title: its name, and its units where it has some."""
    return f"{prm.name} [{prm.units}]" if prm.units not in ("", "1") else prm.name


def _fmt(v: float) -> str:
    return f"{v:.10g}"


class Explorer:
    """One page (one Bokeh session): its widgets, figures and workers."""

    def __init__(self, doc, model="support", method=None, preset=None, sets=None,
                 show=None, slice_param=None):
        from bokeh.models import Div

        self.doc = doc
        self.model = None
        self.values: dict[str, float] = {}
        self.method = method
        self.u0: list[float] = []
        self.pair = (0, 1)
        self._drawn_gen = 0
        self._show_names = show
        self.message = Div(text="", name="message", styles={"color": "#b00020"})
        self._view_worker = compute.LatestWorker(
            self._compute_view,
            self._deliver("_view_worker", self._show_view, "status", "failed: "), "explore-view")
        self._slice_worker = compute.LatestWorker(
            self._compute_slice,
            self._deliver("_slice_worker", self._show_slice, "slice_status",
                          "orbit diagram failed: "),
            "explore-slice", defer_to=self._view_worker)
        self._build_static()
        self.load_model(model, method=method, preset=preset, sets=sets, slice_param=slice_param)
        doc.add_root(self.layout)
        doc.title = "nonsmooth explore"
        doc.on_session_destroyed(lambda ctx: self.stop())

    # ---- workers ------------------------------------------------------------------------------
    def stop(self) -> None:
        self._view_worker.stop()
        self._slice_worker.stop()

    def _deliver(self, worker: str, apply, status: str, failed: str):
        """A worker's ``deliver``: on the page's next tick, drop a result of a request that is
        no longer the newest, show a failure in the Div ``status``, else ``apply`` it."""
        def show(gen, value):
            if not getattr(self, worker).alive(gen):
                return
            if isinstance(value, Exception):
                getattr(self, status).text = f"{failed}{_one_line(value)}"
                return
            apply(gen, value)

        def deliver(gen, value):
            self.doc.add_next_tick_callback(partial(show, gen, value))
        return deliver

    def _params(self):
        return self.model.params(**self.values)

    def _compute_view(self, params, method, u0, alive):
        return compute.orbit_stages(params, method, u0)

    def _compute_slice(self, params, method, param, values, u0, component, alive):
        return compute.orbit_slice(params, method, param, values, u0, alive=alive,
                                   component=component)

    # ---- layout -------------------------------------------------------------------------------
    def _build_static(self):
        from bokeh.layouts import column, row
        from bokeh.models import (Button, ColumnDataSource, Div, Select, Span, TextInput,
                                  TextAreaInput)
        from bokeh.plotting import figure

        self.model_input = TextInput(title="model (built-in name or path/to/file.py:NAME)",
                                     name="model", width=330)
        self.model_input.on_change("value", lambda a, o, n: self._on_model(n))
        self.method_select = Select(title="method", name="method", width=160)
        self.method_select.on_change("value", lambda a, o, n: self._on_method(n))
        self.params_box = column(name="parameters")
        self.u0_box = column(name="initial_condition")
        self.status = Div(text="", name="status", width=520)
        self.modes = Div(text="", name="modes", width=520)
        self.slice_status = Div(text="", name="slice_status", width=520)

        tools = "pan,wheel_zoom,box_zoom,reset"    # clicks arrive as Tap events
        self.time_src = ColumnDataSource(dict(t=[], a=[], color=[]), name="time_source")
        self.orbit_src = ColumnDataSource(dict(a=[], b=[], color=[]), name="orbit_source")
        self.section_src = ColumnDataSource(dict(a=[], b=[]), name="section_source")
        self.slice_src = ColumnDataSource(dict(value=[], point=[]), name="slice_source")
        self.time_fig = figure(title="time response", height=300, width=560, tools=tools,
                               x_axis_label="t", name="time_response")
        self.time_fig.line("t", "a", source=self.time_src, color="#999999")
        self.time_fig.scatter("t", "a", source=self.time_src, color="color", size=3)
        self.phase_fig = figure(title="phase portrait and section (click: initial condition)",
                                height=300, width=460, tools=tools, name="phase_portrait")
        self.phase_fig.line("a", "b", source=self.orbit_src, color="#999999")
        self.phase_fig.scatter("a", "b", source=self.orbit_src, color="color", size=3)
        self.phase_fig.scatter("a", "b", source=self.section_src, color="black", size=5,
                               marker="circle", legend_label="section")
        self.phase_fig.legend.location = "top_left"
        self.slice_fig = figure(title="orbit diagram (click: set the parameter)", height=300,
                                width=1030, tools=tools, name="orbit_diagram")
        self.slice_fig.scatter("value", "point", source=self.slice_src, size=2, color="black")
        self.slice_marker = Span(dimension="height", location=0.0, line_color="#d62728",
                                 line_dash="dashed")
        self.slice_fig.add_layout(self.slice_marker)
        self.level_spans = []
        from bokeh.events import Tap
        self.phase_fig.on_event(Tap, self._on_phase_tap)
        self.slice_fig.on_event(Tap, self._on_slice_tap)

        self.slice_param = Select(title="orbit diagram over", name="slice_param", width=160)
        self.slice_lo = TextInput(title="from", name="slice_from", width=110)
        self.slice_hi = TextInput(title="to", name="slice_to", width=110)
        self.slice_n = TextInput(title="values", name="slice_values", value=str(SLICE_VALUES),
                                 width=80)
        for w in (self.slice_lo, self.slice_hi, self.slice_n):
            w.on_change("value", lambda a, o, n: self.request_slice())
        self.slice_param.on_change("value", lambda a, o, n: self._on_slice_param(n))

        self.export_button = Button(label="export", name="export", width=100)
        self.export_button.on_click(self.export)
        self.export_text = TextAreaInput(title="command line and Python snippet", rows=8,
                                         width=1030, name="export_text")
        head = Div(text="<b>nonsmooth explore</b>", width=200)
        controls = column(head, self.model_input, self.method_select, self.params_box,
                          Div(text="<b>initial condition</b>"), self.u0_box, self.message,
                          width=350)
        panels = column(
            self.modes, row(self.time_fig, self.phase_fig), self.status,
            row(self.slice_param, self.slice_lo, self.slice_hi, self.slice_n), self.slice_status,
            self.slice_fig, row(self.export_button), self.export_text)
        self.layout = row(controls, panels)

    # ---- the model and its widgets ------------------------------------------------------------
    def load_model(self, name, method=None, preset=None, sets=None, slice_param=None,
                   loaded=None) -> bool:
        """Show ``name``'s parameters (``loaded``: the model, already loaded); on failure the
        page says why in one line and keeps the model it had."""
        from ..models import model as get_model

        try:
            m = loaded if loaded is not None else get_model(name)
            params = m.preset(preset) if preset else m.params()
            if sets:
                params = params.replace(**sets)
            if method is not None and method not in m.methods:
                raise ParameterError(f"method: {method!r} is not a method of {m.name} "
                                     f"({', '.join(m.methods)})")
        except (NonsmoothError, TypeError, ValueError) as exc:
            self.message.text = f"model {html.escape(str(name))}: {_one_line(exc)}"
            self.model_input.value = self.model_name if self.model is not None else str(name)
            return False
        names = m.state_names
        pair = (0, 1)
        if self._show_names and all(x in names for x in self._show_names):
            pair = tuple(names.index(x) for x in self._show_names)
        self.message.text = ""
        self._view_worker.cancel()
        self._slice_worker.cancel()
        self.model, self.model_name, self.pair = m, str(name), pair
        self.values = dict(params.as_dict())
        self.method = method or ("smooth" if "smooth" in m.methods else next(iter(m.methods)))
        self.u0 = [0.0] * len(m.state_names)
        self.model_input.value = str(name)
        self.modes.text = "modes: " + " ".join(
            f"<span style='color:{MODE_COLORS[k % len(MODE_COLORS)]}'>&#9632;</span> {nm}"
            for k, nm in enumerate(m.mode_names))
        self.method_select.options = list(m.methods)
        self.method_select.value = self.method
        self._build_param_widgets()
        self._build_u0_widgets()
        self.time_fig.yaxis.axis_label = names[self.pair[0]]
        self.phase_fig.xaxis.axis_label = names[self.pair[0]]
        self.phase_fig.yaxis.axis_label = names[self.pair[1]]
        opts = list(m.param_names)
        default = slice_param or m.forcing_param or opts[0]
        self.slice_param.options = opts
        self._set_slice_param(default if default in opts else opts[0])
        self.request_view()
        return True

    def _build_param_widgets(self):
        from bokeh.layouts import row
        from bokeh.models import Slider, TextInput

        self.fields, self.sliders, self.log_sliders = {}, {}, set()
        rows = []
        for prm in self.model.parameters:
            v = self.values[prm.name]
            lo, hi, log = slider_scale(prm, v)
            if log:
                self.log_sliders.add(prm.name)
                v = math.log10(v)
            field = TextInput(title=_label(prm), value=_fmt(self.values[prm.name]),
                              name=f"param_{prm.name}", width=120)
            slider = Slider(start=lo, end=hi, value=min(max(v, lo), hi),
                            step=(hi - lo) / SLIDER_STEPS, title="", show_value=False,
                            name=f"slider_{prm.name}", width=200)
            field.on_change("value", partial(self._on_field, prm))
            slider.on_change("value_throttled", partial(self._on_slider, prm))
            self.fields[prm.name], self.sliders[prm.name] = field, slider
            rows.append(row(field, slider))
        self.params_box.children = rows

    def _build_u0_widgets(self):
        from bokeh.models import TextInput

        self.u0_fields = []
        for i, nm in enumerate(self.model.state_names):
            w = TextInput(title=f"{nm}(0)", value=_fmt(self.u0[i]), name=f"u0_{nm}", width=120)
            w.on_change("value", partial(self._on_u0, i))
            self.u0_fields.append(w)
        self.u0_box.children = list(self.u0_fields)

    # ---- events -------------------------------------------------------------------------------
    def _on_model(self, name):
        name = name.strip()
        if not name or (self.model is not None and name == self.model_name):
            return
        # loading a user model compiles it (seconds, minutes on an empty cache): in a thread,
        # so that the page (and every other session) stays responsive
        self.message.text = f"loading model {html.escape(name)} ..."
        self.message.styles = {"color": "#555555"}

        def load():
            from ..models import model as get_model
            try:
                m, err = get_model(name), None
            except (NonsmoothError, TypeError, ValueError) as exc:
                m, err = None, exc
            self.doc.add_next_tick_callback(partial(self._loaded, name, m, err))
        threading.Thread(target=load, name="explore-load-model", daemon=True).start()

    def _loaded(self, name, m, err):
        self.message.styles = {"color": "#b00020"}
        if err is not None:
            self.message.text = f"model {html.escape(name)}: {_one_line(err)}"
            self.model_input.value = self.model_name
            return
        self.load_model(name, loaded=m)

    def _on_method(self, name):
        if name and name != self.method:
            self.method = name
            self.request_view()
            self.request_slice()

    def _on_field(self, prm, attr, old, new):
        field = self.fields[prm.name]
        try:
            v = prm.check(new.strip())
            self.model.validate({**self.values, prm.name: v})
        except ParameterError as exc:
            field.title = f"⚠ {str(exc).splitlines()[0]}"     # a title is text, not HTML
            return
        field.title = _label(prm)
        self.set_param(prm.name, v, from_field=True)

    def _on_slider(self, prm, attr, old, new):
        v = 10.0 ** float(new) if prm.name in self.log_sliders else float(new)
        self.fields[prm.name].value = _fmt(v)    # validated by the field

    def _on_u0(self, i, attr, old, new):
        w = self.u0_fields[i]
        nm = self.model.state_names[i]
        try:
            v = float(new)
            if not math.isfinite(v):
                raise ValueError
        except ValueError:
            w.title = f"⚠ {nm}(0): expected a finite number, got {new!r}"
            return
        w.title = f"{nm}(0)"
        if v != self.u0[i]:
            self.u0[i] = v
            self.request_view()
            self.request_slice()

    def _on_phase_tap(self, event):
        a, b = self.pair
        self.u0[a], self.u0[b] = float(event.x), float(event.y)
        self.u0_fields[a].value = _fmt(self.u0[a])     # equal to u0 now: no second request
        self.u0_fields[b].value = _fmt(self.u0[b])
        self.request_view()
        self.request_slice()

    def _on_slice_tap(self, event):
        name = self.slice_param.value
        self.fields[name].value = _fmt(float(event.x))

    def _on_slice_param(self, name):
        if name:
            self._set_slice_param(name)

    def _set_slice_param(self, name):
        v = self.values[name]
        lo, hi = slice_range(self.model, self.values, name)
        self.slice_param.value = name
        self.slice_lo.value, self.slice_hi.value = _fmt(lo), _fmt(hi)
        self.slice_fig.xaxis.axis_label = name
        self.slice_marker.location = v
        self.request_slice()

    def set_param(self, name: str, value: float, from_field: bool = False):
        """Set a parameter (validated by the caller) and recompute what depends on it."""
        if self.values.get(name) == value:
            return
        self.values[name] = value
        if not from_field:
            self.fields[name].value = _fmt(value)
        s = self.sliders[name]
        x = value if name not in self.log_sliders else math.log10(value) if value > 0 else None
        if x is not None:
            if not s.start <= x <= s.end:
                lo, hi = min(s.start, x), max(s.end, x)
                s.update(start=lo, end=hi, step=(hi - lo) / SLIDER_STEPS)
            s.value = x
        if name == self.slice_param.value:
            self.slice_marker.location = value
        self.request_view()
        if name != self.slice_param.value:
            self.request_slice()

    # ---- requests and results -----------------------------------------------------------------
    def request_view(self):
        """Recompute the current orbit (the newest request wins)."""
        try:
            params = self._params()
        except ParameterError as exc:
            self._view_worker.cancel()
            self.status.text = f"⚠ {_one_line(exc)}"
            return
        self.status.text = "computing ..."
        self._view_worker.submit(params, self.method, list(self.u0))

    def request_slice(self):
        """Recompute the orbit-diagram slice (cleared, then filled chunk by chunk)."""
        if self.model is None or not self.slice_param.value:
            return
        name = self.slice_param.value
        prm = self.model.param(name)
        self.slice_src.data = dict(value=[], point=[])
        try:
            params = self._params()
            if not compute.has_section(params):
                raise ParameterError(compute.NO_SECTION)
            lo, hi = prm.check(self.slice_lo.value), prm.check(self.slice_hi.value)
            for end in (lo, hi):
                self.model.validate({**self.values, name: end})
            try:
                n = int(self.slice_n.value)
            except ValueError:
                raise ParameterError(f"values: expected a whole number, got "
                                     f"{self.slice_n.value!r}") from None
            if not 2 <= n <= 5000:
                raise ParameterError(f"values: between 2 and 5000, got {n}")
            if not hi > lo:
                raise ParameterError(f"slice: 'to' must be above 'from' ({lo:g} .. {hi:g})")
        except ParameterError as exc:
            self._slice_worker.cancel()
            self.slice_status.text = f"⚠ {_one_line(exc)}"
            return
        self._slice_total = n
        self._slice_done = 0
        self.slice_status.text = f"orbit diagram: 0 of {n} values"
        component = self.pair[0] if self.pair[0] in (0, 1) else 0
        self.slice_fig.yaxis.axis_label = f"{self.model.state_names[component]} on the section"
        self._slice_worker.submit(params, self.method, name, np.linspace(lo, hi, n),
                                  list(self.u0), component)

    def _show_view(self, gen, orbit):
        summary = (f"{html.escape(orbit.summary())} <span style='color:#888'>"
                   f"({1000 * orbit.seconds:.0f} ms)</span>")
        if gen == self._drawn_gen:      # the second stage: the same orbit with its lambda1
            self.status.text = summary
            return
        self._drawn_gen = gen
        names = self.model.state_names
        a, b = (names[i] for i in self.pair)
        colors = [MODE_COLORS[int(m) % len(MODE_COLORS)] for m in orbit.mode]
        self.time_src.data = dict(t=orbit.t, a=orbit.u.get(a, []), color=colors)
        self.orbit_src.data = dict(a=orbit.u.get(a, []), b=orbit.u.get(b, []), color=colors)
        self.section_src.data = dict(a=orbit.section.get(a, []), b=orbit.section.get(b, []))
        self._draw_levels()
        self.status.text = summary

    def _draw_levels(self):
        from bokeh.models import Span

        for s in self.level_spans:
            s.visible = False
        if self.pair[0] != 0:
            return
        try:
            lines = self.model.plot_lines(self._params(), self.method)
        except Exception:  # noqa: BLE001 - decoration only
            lines = []
        for k, (level, _label) in enumerate(lines[:4]):
            if k >= len(self.level_spans):
                spans = (Span(dimension="width", line_color="#555555", line_dash="dotted"),
                         Span(dimension="height", line_color="#555555", line_dash="dotted"))
                self.time_fig.add_layout(spans[0])
                self.phase_fig.add_layout(spans[1])
                self.level_spans.extend(spans)
            for s in self.level_spans[2 * k:2 * k + 2]:
                s.location, s.visible = float(level), True

    def _show_slice(self, gen, part):
        values, pts, _period = part
        vv = np.repeat(values, pts.shape[1])
        pp = pts.reshape(-1)
        ok = np.isfinite(pp)
        self.slice_src.stream(dict(value=vv[ok], point=pp[ok]))
        self._slice_done += len(values)
        done = self._slice_done >= self._slice_total
        self.slice_status.text = (f"orbit diagram: {self._slice_done} of {self._slice_total} "
                                  f"values{' (complete)' if done else ''}")

    # ---- export -------------------------------------------------------------------------------
    def export(self):
        """The current parameters as a ``nonsmooth`` command line and a Python snippet."""
        names = self.model.state_names
        show = None if self.pair == (0, 1) else tuple(names[i] for i in self.pair)
        self.export_text.value = export_text(self.model_name, self.model, self.values,
                                             self.method, self.u0, show=show)


def export_text(model_name: str, model, values: dict, method: str, u0, show=None) -> str:
    """A command line and a Python snippet that compute what the page shows: ``poincare``
    with the page's transient and record (a model without a section: ``simulate`` over the
    periods drawn, after the same transient), from the same state, showing the same pair of
    components (``show``)."""
    sets = " ".join(f"--set {k}={_fmt(v)}" for k, v in values.items())
    names = model.state_names
    u0_arg = ",".join(f"{n}={_fmt(x)}" for n, x in zip(names, u0))
    forced = compute.has_section(model.params(**values))
    tr, rec = compute.VIEW_TRANSIENT, compute.VIEW_RECORD
    periods = compute.VIEW_PERIODS if model.omega or model.period else compute.AUTONOMOUS_TIME
    cmd = (f"poincare --record {rec} --transient {tr}" if forced else
           f"simulate --periods {periods} --transient {tr}")
    show_arg = f" --show {','.join(show)}" if show else ""
    line = (f"nonsmooth {cmd} --model {shlex.quote(model_name)} --method {method} {sets} "
            f"--u0 {u0_arg}{show_arg} -o explore.nc --plot explore.png")
    kw = ", ".join(f"{k}={_fmt(v)}" for k, v in values.items())
    call = (f"ns.poincare(p, record={rec}, transient={tr}" if forced else
            f"ns.simulate(p, periods={periods}, transient={tr}")
    figure = "plot_poincare" if forced else "plot_time_response"
    show_kw = f", show={tuple(show)!r}" if show else ""
    py = (f"import nonsmooth as ns\n\n"
          f"p = ns.model({model_name!r}).params({kw})\n"
          f"ds = {call}, method={method!r}, u0={[float(x) for x in u0]!r})\n"
          f"fig = ns.plot.{figure}(ds{show_kw})\n")
    return f"{line}\n\n{py}"


def make_document(doc, model="support", method=None, preset=None, sets=None, show=None,
                  slice_param=None) -> Explorer:
    """Build the explore page in the Bokeh document ``doc`` (a Bokeh server application's
    document): ``model`` a built-in name or ``path/to/file.py:NAME``, its ``method``,
    ``preset`` and parameter overrides ``sets`` ({name: value}), the two state components to
    ``show`` (names) and the parameter of the orbit-diagram slice (default: the forcing
    frequency)."""
    return Explorer(doc, model=model, method=method, preset=preset, sets=sets, show=show,
                    slice_param=slice_param)
