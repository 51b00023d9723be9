"""Basin entropy and the uncertainty exponent (``ns.basin_entropy``, issue 21 item 1) against
oracles: synthetic label images whose values are known (a straight or round boundary:
alpha = 1; two labels at random: S_b = ln 2 less the plug-in estimator's bias; one label: 0),
and two forced double wells, one whose basin boundary is smooth (alpha = 1, S_bb < ln 2) and
one whose boundary is fractal (S_bb > ln 2, alpha well below 1)."""

import math

import numpy as np
import pytest
import xarray as xr

import nonsmooth as ns
from nonsmooth.errors import ParameterError

from cli_helpers import one_line, run_cli

pytestmark = pytest.mark.filterwarnings("ignore::numba.NumbaExperimentalFeatureWarning")

LN2 = math.log(2.0)


def grid(n=400):
    return np.meshgrid(np.arange(n), np.arange(n), indexing="ij")


def test_a_straight_and_a_round_boundary_have_exponent_one():
    x, y = grid()
    for lab in ((x * math.cos(0.3) + y * math.sin(0.3) > 200).astype(int),
                ((x - 200) ** 2 + (y - 180) ** 2 < 120 ** 2).astype(int)):
        d = ns.basin_entropy(lab, 5)
        a, se = float(d.uncertainty_exponent), float(d.uncertainty_exponent_stderr)
        assert abs(a - 1.0) <= max(3 * se, 0.03), (a, se)
        assert 0 < float(d.boundary_basin_entropy) < LN2
        assert int(d.fractal_boundary) == 0
        # S_b = S_bb N_b / N: the boundary boxes are a thin share of all boxes
        assert float(d.basin_entropy) == pytest.approx(
            float(d.boundary_basin_entropy) * int(d.boundary_boxes) / int(d.boxes))
        assert int(d.boundary_boxes) < 0.05 * int(d.boxes)


def test_two_labels_at_random_have_entropy_ln2_and_one_label_none():
    rng = np.random.default_rng(7)
    lab = rng.integers(0, 2, (400, 400))
    d = ns.basin_entropy(lab, 20)  # 400 cells a box: the estimator's bias is 1 / 800
    assert float(d.basin_entropy) == pytest.approx(LN2 - 1.0 / 800, abs=1e-3)
    assert float(d.boundary_basin_entropy) == float(d.basin_entropy)
    assert int(d.fractal_boundary) == 0  # two basins: S_bb <= ln 2, the criterion cannot hold
    assert 0.0 <= float(d.uncertainty_exponent) < 0.1  # boxes of 3 cells on meet it: alpha 0
    three = ns.basin_entropy(rng.integers(0, 3, (400, 400)), 20)
    assert float(three.basin_entropy) == pytest.approx(math.log(3) - 2.0 / 800, abs=1.5e-3)
    assert int(three.fractal_boundary) == 1
    one = ns.basin_entropy(np.zeros((50, 40), int), 5)
    assert float(one.basin_entropy) == 0.0 and float(one.boundary_basin_entropy) == 0.0
    assert int(one.boundary_boxes) == 0 and int(one.boxes) == 80
    assert math.isnan(float(one.uncertainty_exponent))


def test_undecided_cells_are_left_out_of_the_shares():
    lab = np.zeros((10, 10), int)
    lab[:5, 5:] = 1  # box (0, 1) all 1; box (0, 0) all 0
    lab[5:, :5] = np.array([0, 1, 0, 1, -1] * 5).reshape(5, 5)  # a 10/10 mix and 5 undecided
    lab[5:, 5:] = -1  # no decided cell: not a box
    d = ns.basin_entropy(lab, 5, epsilons=[2, 5])
    assert int(d.boxes) == 3 and int(d.boundary_boxes) == 1
    assert float(d.box_entropy[1, 0]) == pytest.approx(LN2)
    assert math.isnan(float(d.box_entropy[1, 1]))
    assert float(d.basin_entropy) == pytest.approx(LN2 / 3)


def double_well():
    return ns.model_from_equations(
        "double_well", states=("X", "V"),
        parameters={"delta": 0.15, "F0": 0.25, "omega": 1.0},
        modes={"free": ["V", "-delta*V + X - X**3 + F0*cos(omega*t)"]}, method="smooth")


def test_a_smooth_and_a_fractal_basin_boundary_of_the_forced_double_well():
    """Unforced with strong damping (delta = 0.6): two wells whose basins are separated by
    the saddle's stable manifold, a smooth curve; forced (delta = 0.15, F0 = 0.25, omega = 1):
    three attractors with intermingled basins (Daza et al. 2016 use this oscillator)."""
    m = double_well()
    b = ns.basins(m.params(delta=0.6, F0=0.0), x=(-2, 2), v=(-2, 2), grid=80, method="smooth",
                  lyapunov=False)
    assert b.sizes["attractor"] == 2 and float(b.undecided_fraction) == 0.0
    d = ns.basin_entropy(b, 10)  # 100 cells a box: the entropies' bias is below 0.01
    a, se = float(d.uncertainty_exponent), float(d.uncertainty_exponent_stderr)
    assert abs(a - 1.0) <= 3 * se + 0.03, (a, se)
    assert float(d.boundary_basin_entropy) < LN2 and int(d.fractal_boundary) == 0
    assert d.attrs["model"] == "double_well" and d.attrs["analysis"] == "basin_entropy"
    assert d["box_entropy"].dims == ("box_x0", "box_v0") and d.sizes["box_x0"] == 8
    f = ns.basins(m.params(), x=(-2, 2), v=(-2, 2), grid=80, method="smooth", lyapunov=False)
    assert f.sizes["attractor"] == 3
    e = ns.basin_entropy(f, 10)
    assert float(e.boundary_basin_entropy) > LN2 + 0.02 and int(e.fractal_boundary) == 1
    assert float(e.uncertainty_exponent) < 0.5
    assert float(e.basin_entropy) > 0.5  # nearly every box mixes the basins


def test_cli_basins_entropy_writes_the_variables_and_the_figure(tmp_path, capsys):
    out, fig = tmp_path / "b.nc", tmp_path / "ent.png"
    code, text, err = run_cli(["basins", "--preset", "fig7", "--grid", "24", "--x", "-1", "2",
                               "--v", "-2", "2", "--entropy-plot", str(fig), "--box", "4",
                               "-o", str(out)], capsys)
    assert code == 0, err
    assert "basin entropy S_b = " in text and "uncertainty exponent alpha = " in text
    assert fig.is_file() and fig.stat().st_size > 10_000
    with xr.open_dataset(out) as ds:
        d = ns.basin_entropy(ds, 4)
        assert float(ds.basin_entropy) == float(d.basin_entropy)
        assert ds.attrs["entropy_box"] == 4 and ds.attrs["analysis"] == "basins"
        assert ds["label"].shape == (24, 24)


@pytest.mark.parametrize("args, field", [
    (["--entropy", "--box", "1"], "box:"),
    (["--entropy", "--box", "30"], "box:"),
])
def test_cli_entropy_bad_box_is_one_line(args, field, tmp_path, capsys):
    code, _, err = run_cli(["basins", "--preset", "fig7", "--grid", "24", *args,
                            "-o", str(tmp_path / "b.nc")], capsys)
    assert code == 2
    one_line(err, field)


def test_bad_labels_and_boxes_are_one_line_errors():
    with pytest.raises(ParameterError, match="2-D grid"):
        ns.basin_entropy(np.zeros(10, int))
    with pytest.raises(ParameterError, match="integers"):
        ns.basin_entropy(np.full((10, 10), 0.5))
    with pytest.raises(ParameterError, match="box:"):
        ns.basin_entropy(np.zeros((10, 10), int), 11)
    with pytest.raises(ParameterError, match="epsilons:"):
        ns.basin_entropy(np.zeros((10, 10), int), 5, epsilons=[1, 2])
    with pytest.raises(ParameterError, match="no 'label'"):
        ns.basin_entropy(xr.Dataset({"x": ("a", [1, 2])}))


def test_surface_basins_read_with_x_first():
    """``surface_basins`` stores its labels over (v0, x0): read with X first, as ``basins``."""
    lab = np.zeros((6, 10), np.int32)  # (v0, x0)
    lab[:, 5:] = 1  # a boundary at x0 index 5
    ds = xr.Dataset({"label": (("v0", "x0"), lab)},
                    coords={"v0": np.linspace(-1, 1, 6), "x0": np.linspace(-1, 1, 10)})
    d = ns.basin_entropy(ds, 2, epsilons=[2, 3, 4])
    assert d["box_entropy"].dims == ("box_x0", "box_v0")
    assert d.sizes["box_x0"] == 5 and d.sizes["box_v0"] == 3
    assert int(d.boundary_boxes) == 3  # the column of boxes over x0 = 4, 5


def test_small_grids_and_repeated_box_sides():
    """The default box sides fit any grid (a 3 x 3 grid: too few sizes, alpha NaN); repeated
    sides count once; a side that is not an integer is refused."""
    d = ns.basin_entropy(np.array([[0, 0, 1], [0, 1, 1], [1, 1, 1]]), 2)
    assert math.isnan(float(d.uncertainty_exponent)) and int(d.boxes) == 1
    x, y = grid(64)
    lab = (x + 0.3 * y > 40).astype(int)
    a = ns.basin_entropy(lab, 4, epsilons=[2, 3, 3, 4, 6, 8])
    b = ns.basin_entropy(lab, 4, epsilons=[2, 3, 4, 6, 8])
    assert a.epsilon.values.tolist() == [2, 3, 4, 6, 8]
    assert float(a.uncertainty_exponent) == float(b.uncertainty_exponent)
    assert math.isnan(float(ns.basin_entropy(lab, 4, epsilons=[4, 4, 4]).uncertainty_exponent))
    with pytest.raises(ParameterError, match="integers"):
        ns.basin_entropy(lab, 4, epsilons=[2.5, 3, 4])
