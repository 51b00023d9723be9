"""Stable and unstable manifolds of a saddle of the stroboscopic map, and the first homoclinic
tangency along a parameter (``ns.manifolds``, ``ns.homoclinic_tangency``; issue 21, item 2).

Oracles: invariance (a manifold point mapped by the kernel lands on its branch); at Fig. 7's
omega = 1.10 the saddle's stable manifold is the boundary that ``basins`` computes (every
manifold point in the grid has both labels within two cells, every boundary cell lies within
2.5 cells of the manifold) and the unstable branches end on the two attractors; for the forced
double well x'' + delta x' - x + x^3 = F cos t, Melnikov's first-order threshold of the first
homoclinic tangency, F = delta 4 cosh(pi / 2) / (3 sqrt(2) pi)."""

import math

import numpy as np
import pytest
import xarray as xr

import nonsmooth as ns
from cli_helpers import one_line, run_cli
from nonsmooth.errors import ParameterError
from nonsmooth.io import load_dataset

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

ATTRACTORS = [(-0.55703, 0.16048), (0.6567, 1.19366)]  # Fig. 7's two stable orbits
WINDOW = dict(x=(-3.0, 3.0), v=(-3.0, 3.0))


def _branch(ds, b):
    sel = ds.branch.values == b
    return np.c_[ds.X.values[sel], ds.V.values[sel]]


def _distance_to(p, W):
    """Distance from point p to the polyline W (rows)."""
    a, b = W[:-1], W[1:]
    d = b - a
    t = np.clip(((p - a) * d).sum(1) / np.maximum((d * d).sum(1), 1e-300), 0.0, 1.0)
    return float(np.min(np.linalg.norm(a + t[:, None] * d - p, axis=1)))


@pytest.fixture(scope="module")
def fig7():
    p = ns.preset("fig7")
    orbit = ns.periodic_orbit(p, x0=-1.5, v0=0.25)
    return p, orbit, ns.manifolds(p, orbit, **WINDOW)


def test_fig7_stable_manifold_is_the_basin_boundary_and_unstable_ends_on_the_attractors(fig7):
    p, orbit, ds = fig7
    a = ds.attrs
    assert a["status_unstable_plus"] == a["status_unstable_minus"] == \
        "converged onto an attractor"
    assert a["status_stable_plus"] == a["status_stable_minus"] == "left the window"
    assert a["map_periods"] == 1 and ds.sizes["crossing"] == 0  # a smooth boundary
    ends = np.c_[ds.end_X.values[:2], ds.end_V.values[:2]]
    near = [int(np.argmin([math.dist(e, att) for att in ATTRACTORS])) for e in ends]
    assert sorted(near) == [0, 1]  # one branch onto each attractor
    assert max(math.dist(e, ATTRACTORS[k]) for e, k in zip(ends, near)) < 0.01
    b = ns.basins(p, grid=100, method="exact", lyapunov=False, **WINDOW)
    lab = b.label.values
    assert set(np.unique(lab)) == {0, 1}
    x0, v0 = b.x0.values, b.v0.values
    dx, dv = x0[1] - x0[0], v0[1] - v0[0]
    W = np.concatenate([_branch(ds, 2), _branch(ds, 3)])
    inside = (W[:, 0] >= x0[0]) & (W[:, 0] <= x0[-1]) & (W[:, 1] >= v0[0]) & (W[:, 1] <= v0[-1])
    assert inside.sum() > 300
    for x, v in W[inside]:
        i, j = int(round((x - x0[0]) / dx)), int(round((v - v0[0]) / dv))
        assert len(np.unique(lab[max(0, i - 2):i + 3, max(0, j - 2):j + 3])) == 2, (x, v)
    edge = np.zeros(lab.shape, bool)
    edge[:-1] |= lab[:-1] != lab[1:]
    edge[1:] |= lab[:-1] != lab[1:]
    edge[:, :-1] |= lab[:, :-1] != lab[:, 1:]
    edge[:, 1:] |= lab[:, :-1] != lab[:, 1:]
    I, J = np.nonzero(edge)
    far = [min(np.hypot((W[:, 0] - x0[i]) / dx, (W[:, 1] - v0[j]) / dv)) for i, j in zip(I, J)]
    assert len(I) > 300 and max(far) <= 2.5  # the whole boundary is the stable manifold


def test_an_unstable_branch_that_leaves_a_small_window_and_comes_back_is_followed():
    """In the window x in (-1.2, -0.2), v in (0, 1) the branch W^u_+ leaves (a whole level
    outside) and comes back to spiral onto the attractor at (-0.557, 0.160) inside it."""
    p = ns.preset("fig7")
    orbit = ns.periodic_orbit(p, x0=-1.5, v0=0.25)
    ds = ns.manifolds(p, orbit, x=(-1.2, -0.2), v=(0.0, 1.0), spacing=0.01, stable=False)
    assert ds.attrs["status_unstable_plus"] == "converged onto an attractor"
    assert math.dist((float(ds.end_X[0]), float(ds.end_V[0])), ATTRACTORS[0]) < 0.01
    W = _branch(ds, 0)
    inside = (W[:, 0] > -1.2) & (W[:, 0] < -0.2) & (W[:, 1] > 0) & (W[:, 1] < 1)
    steps = np.linalg.norm(np.diff(W, axis=0), axis=1)
    assert steps[inside[1:] & inside[:-1]].max() <= 1.1 * 0.01
    assert ds.sizes["crossing"] == 0 and ds.attrs["stable_method"] == ""


@pytest.mark.parametrize("method", ["exact", "smooth"])
def test_a_manifold_point_mapped_by_the_kernel_lands_on_its_branch(fig7, method):
    p = ns.preset("fig7")
    if method == "exact":
        ds = fig7[2]
    else:
        orbit = ns.periodic_orbit(p, x0=-1.5, v0=0.25, method="smooth")
        ds = ns.manifolds(p, orbit, spacing=0.06, length=6.0, **WINDOW)
    spacing = ds.attrs["spacing"]
    rng = np.random.default_rng(7)
    for b in range(4):
        W = _branch(ds, b)
        assert len(W) > 60
        steps = np.linalg.norm(np.diff(W, axis=0), axis=1)
        assert steps.max() <= 1.1 * spacing  # (the corrector moves a stable point across)
        for i in rng.choice(np.arange(1, len(W) - 20), 8, replace=False):
            r = ns.simulate(p, periods=1, x0=W[i, 0], v0=W[i, 1], method=method,
                            samples_per_period=16)
            img = np.array([float(r.X[-1]), float(r.V[-1])])
            # unstable: the image is a point of the branch (j + s -> j + 1 + s); stable: it
            # lies between two points, within the chord's sagitta (curvature ~ 2)
            assert _distance_to(img, W) <= (1e-7 if b < 2 else spacing ** 2 / 2), (b, i)


def double_well():
    """As tests/test_basin_entropy.py defines it (one compiled model for both files)."""
    return ns.model_from_equations(
        "double_well", states=("X", "V"),
        parameters={"delta": 0.15, "F0": 0.25, "omega": 1.0},
        modes={"free": ["V", "-delta*V + X - X**3 + F0*cos(omega*t)"]}, method="smooth")


def test_the_neimark_sacker_curve_of_an_orbit_in_a_well_is_zero_damping():
    """(issue 21, item 4) The flow's divergence is -delta, so det M = e^(-delta T)
    (Liouville) and the orbit in a well has its complex pair on the unit circle exactly where
    delta = 0, whatever omega: the Neimark-Sacker curve in (delta, omega), continued both ways
    between the strong resonances, is delta = 0."""
    p = double_well().params(delta=0.05, F0=0.03, omega=1.1)
    br = ns.continuation(p, "delta", x0=1.0, bounds=(-0.05, 0.05), direction="down",
                         method="smooth", step=0.02)
    assert br.special_type.values.tolist() == [3]
    for way in ("up", "down"):
        c = ns.neimark_sacker_curve(p, "delta", "omega", start=br, direction=way, step=0.02,
                                    bounds2=(1.02, 1.3))
        assert c.attrs["status"] == "left the bounds of omega"
        assert c.attrs["analysis"] == "neimark_sacker_curve" and c.sizes["point"] > 3
        assert np.max(np.abs(c.delta.values)) < 1e-9
        assert np.max(np.abs(c.multiplier_abs.values - 1.0)) < 1e-9
        assert np.all(np.abs(c.multiplier_imag.values) > 1e-3)  # a complex pair


def test_the_first_homoclinic_tangency_of_the_double_well_is_melnikovs():
    p = double_well().params(delta=0.05, F0=0.03)
    orbit = ns.periodic_orbit(p, x0=-0.015, v0=0.0, method="smooth")
    assert orbit.attrs["converged"] == 1 and float(orbit.multiplier_abs[0]) > 400
    seen = []
    t = ns.homoclinic_tangency(p, orbit, "F0", (0.036, 0.040), tol=2e-4, x=(-2, 2),
                               v=(-1.5, 1.5), length=5.0, spacing=0.05, max_search=60,
                               progress=lambda d, n: seen.append((d, n)))
    assert seen == [(i, 7) for i in range(1, 8)] and t.sizes["evaluation"] == 7
    melnikov = 0.05 * 4 * math.cosh(math.pi / 2) / (3 * math.sqrt(2) * math.pi)  # 0.037651
    assert abs(float(t.F0) / melnikov - 1.0) < 0.005  # the bracket: 2e-4 / 0.0377
    assert float(t.F0_above) - float(t.F0_below) <= 2e-4
    assert t.sizes["crossing"] > 0 and t.n_crossings.values[0] == 0
    assert t.attrs["analysis"] == "homoclinic_tangency" and t.attrs["param"] == "F0"
    with pytest.raises(ParameterError, match="bounds: the manifolds do not cross"):
        ns.homoclinic_tangency(p, orbit, "F0", (0.03, 0.032), x=(-2, 2), v=(-1.5, 1.5),
                               length=2.0, spacing=0.05, max_search=60)


def test_result_file_and_bad_input(fig7, tmp_path):
    p, orbit, ds = fig7
    path = tmp_path / "m.nc"
    ns.io.save_dataset(ds, path)
    got = load_dataset(path)
    xr.testing.assert_equal(got, ds)
    assert got.attrs["analysis"] == "manifolds" and got.attrs["method"] == "exact"
    assert got.branch.attrs["flag_meanings"].split()[0] == "unstable_plus"
    seen = []
    short = ns.manifolds(p, orbit, length=0.2, progress=lambda d, t: seen.append((d, t)))
    assert short.sizes["point"] > 10 and seen[-1] == (4 * 4000, 4 * 4000)
    assert all(0 <= d <= t for d, t in seen) and [d for d, _ in seen] == sorted(
        d for d, _ in seen)
    stable = ns.periodic_orbit(p, x0=0.0, v0=0.0, transient=300)
    for call, field in [
        (lambda: ns.manifolds(p, stable), "orbit: a saddle"),
        (lambda: ns.manifolds(p, ds), "orbit: expected"),
        (lambda: ns.manifolds(p.replace(omega=1.2), orbit), "orbit: computed at omega"),
        (lambda: ns.manifolds(p, orbit, x=(1, 0), v=(0, 1)), "x: expected finite low < high"),
        (lambda: ns.manifolds(p, orbit, x=(0, 1)), "x: give both"),
        (lambda: ns.manifolds(p, orbit, spacing=0.0), "spacing: must be > 0"),
        (lambda: ns.manifolds(p, orbit, iterates=0), "iterates"),
        (lambda: ns.homoclinic_tangency(p, orbit, "omega", (1.1, 1.1)), "bounds"),
        (lambda: ns.homoclinic_tangency(p, orbit, "omega", (1.1, 1.12), stable=False),
         "stable: not an option"),
        (lambda: ns.homoclinic_tangency(p, orbit, "omega", (1.1, 1.12), nope=1), "nope"),
    ]:
        with pytest.raises(ParameterError, match=field):
            call()


def test_cli_manifolds_writes_the_api_result_and_a_figure(tmp_path, capsys, fig7):
    nc, png = tmp_path / "m.nc", tmp_path / "m.png"
    code, out, err = run_cli(["manifolds", "-o", str(nc), "--plot", str(png)], capsys)
    assert code == 0, err
    got = load_dataset(nc)
    np.testing.assert_array_equal(got.X.values, fig7[2].X.values)
    assert "saddle of period 1 at (X, V) = (-0.982138, +0.596784)" in out
    assert "homoclinic points: 0" in out and out.count("converged onto an attractor") == 2
    assert png.read_bytes()[:4] == b"\x89PNG"
    code, out, err = run_cli(["manifolds", "--axes", "V,X", "-o", str(nc)], capsys)
    assert code == 0, err  # the same manifolds in the plane (V, X)
    assert "saddle of period 1 at (V, X) = (+0.596784, -0.982138)" in out
    got = load_dataset(nc)
    assert got.attrs["axes"] == "V X" and got.attrs["stable_method"] == \
        fig7[2].attrs["stable_method"]
    for b in (2, 3):
        assert _near_polyline(_branch(fig7[2], b), _branch(got, b)) < 1e-5
    code, out, err = run_cli(["manifolds", "--axes", "X,Q"], capsys)
    assert code == 2
    one_line(err, "axes: unknown component 'Q'")
    code, out, err = run_cli(["manifolds", "--x0", "50", "--v0", "50"], capsys)
    assert code == 1
    one_line(err, "no period-1 orbit found")
    code, out, err = run_cli(["manifolds", "--spacing", "-1"], capsys)
    assert code == 2
    one_line(err, "spacing")


def test_the_manifolds_of_each_point_of_a_period_two_saddle_are_images_of_each_other():
    """Table 4 at F0 = 0.225: the period-2 orbit left unstable by the doubling to period 4
    (a flip saddle, mu = -6.41: grown with P^4). The unstable manifold of its point 1 is the
    image by one forcing period of that of its point 0."""
    p = ns.preset("table4").replace(F0=0.225)
    orbit = ns.periodic_orbit(p, k=2, x0=1.013, v0=0.478)
    assert orbit.attrs["converged"] == 1 and float(orbit.multiplier_real[0]) < -6.0
    kw = dict(x=(0.0, 1.3), v=(-0.5, 1.5), stable=False)
    m0 = ns.manifolds(p, orbit, length=0.5, **kw)
    m1 = ns.manifolds(p, orbit, point=1, length=2.0, **kw)
    assert m0.attrs["map_periods"] == m1.attrs["map_periods"] == 4
    assert m1.attrs["orbit_point"] == 1
    assert abs(float(m1.saddle_X) - float(orbit.X_section[1])) < 1e-9
    assert abs(float(m1.saddle_V) - float(orbit.V_section[1])) < 1e-9
    u1 = m1.where(m1.branch <= 1, drop=True)
    a = np.c_[u1.X.values[:-1], u1.V.values[:-1]]
    ab = np.c_[np.diff(u1.X.values), np.diff(u1.V.values)]
    u0 = m0.where(m0.branch <= 1, drop=True)
    gaps = []
    for i in np.linspace(0, u0.sizes["point"] - 1, 12).astype(int):
        d = ns.simulate(p, periods=1, samples_per_period=1, method="exact", x0=float(u0.X[i]),
                        v0=float(u0.V[i]), rtol=1e-10, atol=1e-12)
        q = np.array([float(d.X[-1]), float(d.V[-1])])
        t = np.clip(((q - a) * ab).sum(1) / np.maximum((ab * ab).sum(1), 1e-300), 0.0, 1.0)
        gaps.append(np.min(np.hypot(*(a + t[:, None] * ab - q).T)))
    spacing = m1.attrs["spacing"]
    assert max(gaps) < spacing / 10 and np.median(gaps) < 1e-5  # chords' sagitta; 8e-6
    with pytest.raises(ParameterError, match="point: a period-2 orbit has section points 0"):
        ns.manifolds(p, orbit, point=2, **kw)


def double_well_with_oscillator():
    """The double well of double_well() and a damped linear oscillator (Y, W), coupled both
    ways by eps: a four-dimensional section."""
    return ns.model_from_equations(
        "double_well_4", states=("X", "V", "Y", "W"),
        parameters={"delta": 0.15, "F0": 0.25, "omega": 1.0, "eps": 0.0},
        modes={"free": ["V", "-delta*V + X - X**3 + F0*cos(omega*t) + eps*(Y - X)",
                        "W", "-0.4*W - Y + eps*(X - Y)"]}, method="smooth")


from nonsmooth.analysis.manifolds import BRANCH_NAMES as BRANCHES  # noqa: E402


def _near_polyline(W, pts):
    """Largest distance from the rows of pts to the polyline W."""
    return max(_distance_to(q, W) for q in pts)


def test_the_stable_manifold_of_a_four_dimensional_section_is_traced_in_a_plane():
    """n > 2: the saddle's stable manifold is a hypersurface of the section, traced where it
    meets the plane of two components through the saddle. Oracles: uncoupled (eps = 0) it is
    W^s(double well) x R^2, so its trace in (X, V) is the double well's own stable manifold
    and its trace in (X, Y) the line X = X* (V = V*); coupled (eps = 0.2) the trace in (X, V)
    is the boundary that basins draws in that plane through the saddle."""
    kw = dict(x=(-2, 2), v=(-1.5, 1.5), length=3.0, spacing=0.05, max_search=60)
    p2 = double_well().params(delta=0.05, F0=0.03)
    o2 = ns.periodic_orbit(p2, x0=-0.015, v0=0.0, method="smooth")
    d2 = ns.manifolds(p2, o2, **kw)
    m4 = double_well_with_oscillator()
    p4 = m4.params(delta=0.05, F0=0.03)
    o4 = ns.periodic_orbit(p4, u0=[-0.015, 0.0, 0.0, 0.0], method="smooth")
    assert o4.attrs["converged"] == 1 and o4.sizes["multiplier"] == 4
    d4 = ns.manifolds(p4, o4, **kw)
    assert "trace of the 3-dimensional stable manifold in the plane (X, V)" in \
        d4.attrs["stable_method"]
    for b in (2, 3):  # the same curve, to the search's tolerance (measured 8e-12)
        W2, W4 = _branch(d2, b), _branch(d4, b)
        assert len(W4) > 50 and _near_polyline(W2, W4) < 1e-6
        assert np.all(d4.Y.values[d4.branch.values == b] == 0.0)
    for b in (0, 1):  # the unstable branches too (4-D integration: its own steps)
        assert _near_polyline(_branch(d2, b), _branch(d4, b)[::10]) < 1e-4
    yx = ns.manifolds(p4, o4, axes="V,X", x=(-1.5, 1.5), v=(-2, 2), length=3.0, spacing=0.05,
                      max_search=60)  # the plane (V, X): the same curves
    assert yx.attrs["axes"] == "V X" and yx.attrs["section_coordinates"] == 4
    for b in (2, 3):
        assert _near_polyline(_branch(d4, b), _branch(yx, b)) < 1e-5
    # (beyond |Y| = 0.88 its points leave the saddle before they reach its box: "lost")
    xy = ns.manifolds(p4, o4, axes="X,Y", x=(-2, 2), v=(-1, 1), length=0.6, spacing=0.05,
                      max_search=60)
    assert xy.attrs["axes"] == "X Y" and xy.component_index.values.tolist() == ["X", "Y"]
    for b in (2, 3):
        sel = xy.branch.values == b
        assert xy.attrs[f"status_{BRANCHES[b]}"] == "length: 0.6 reached"
        assert sel.sum() > 15 and np.ptp(xy.Y.values[sel]) > 0.59
        assert np.max(np.abs(xy.X.values[sel] - float(xy.saddle_X))) < xy.attrs["tol"]  # 1.2e-6
        assert np.all(xy.V.values[sel] == float(xy.saddle_V))

    # coupled: the trace is the boundary of the basins in its plane
    p = m4.params(delta=0.6, F0=0.1, eps=0.2)
    o = ns.periodic_orbit(p, u0=[0.0, 0.0, 0.0, 0.0], method="smooth")
    d = ns.manifolds(p, o, x=(-2, 2), v=(-2, 2))
    assert d.attrs["status_stable_plus"] == d.attrs["status_stable_minus"] == "left the window"
    zs = [float(c) for c in ns.io.components(d, prefix="saddle_").values]
    assert abs(zs[2]) > 1e-3  # the plane's fixed components are not zero
    b = ns.basins(p, x=(-2, 2), v=(-2, 2), grid=60, method="smooth", lyapunov=False,
                  axes=("X", "V"), u0=zs)
    lab = b.label.values
    assert set(np.unique(lab)) == {0, 1}
    x0, v0 = b.x0.values, b.v0.values
    W = np.concatenate([_branch(d, 2), _branch(d, 3)])
    inside = (np.abs(W[:, 0]) <= 2) & (np.abs(W[:, 1]) <= 2)
    assert inside.sum() > 200
    for x, v in W[inside]:
        i = int(round((x - x0[0]) / (x0[1] - x0[0])))
        j = int(round((v - v0[0]) / (v0[1] - v0[0])))
        assert len(np.unique(lab[max(0, i - 2):i + 3, max(0, j - 2):j + 3])) == 2, (x, v)

    with pytest.raises(ParameterError, match="orbit: the first homoclinic tangency is sought "
                                             "for a two-dimensional section"):
        ns.homoclinic_tangency(p4, o4, "F0", (0.03, 0.045))
    with pytest.raises(ParameterError, match="axes: unknown component 'Z'"):
        ns.manifolds(p4, o4, axes="X,Z")
