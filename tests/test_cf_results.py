"""Issue 8 item 7: result files of simulate, poincare, bifurcation, resonance, eta_study and maps
follow CF (checked with cf_xarray and pint's UDUNITS parsing) and one naming scheme."""

import numpy as np
import pytest

import nonsmooth as ns
from nonsmooth.analysis.bifurcation import bifurcation_diagram
from nonsmooth.analysis.eta_study import eta_study
from nonsmooth.analysis.poincare import poincare
from nonsmooth.analysis.resonance import resonance_curve

cfx = pytest.importorskip("cf_xarray")


def _datasets():
    p3 = ns.preset("table3").replace(omega=0.91)
    return {
        "simulate": ns.simulate(ns.preset("table1"), periods=1, transient=5, samples_per_period=20),
        "poincare": poincare(p3, record=12, transient=50, orbit_samples=10),
        "bifurcation": bifurcation_diagram(p3, "omega", [0.9, 0.91], transient=20, record=6),
        "resonance": resonance_curve(ns.preset("fig6a"), [0.9, 1.0], transient=10, record=4),
        "eta_study": eta_study(ns.preset("fig6a"), [0.1, 0.01], transient=10, record=6,
                               orbit_periods=1, samples_per_period=8),
        "parameter_map": ns.parameter_map(p3, x=("omega", 0.9, 0.92, 3),
                                          y=("F0", 0.3, 0.31, 2), transient=20, record=6),
    }


@pytest.fixture(scope="module")
def datasets(tmp_path_factory):
    d = tmp_path_factory.mktemp("cf")
    # read back from netCDF: what other tools see
    return {k: ns.io.load_dataset(ns.io.save_dataset(ds, d / f"{k}.nc"))
            for k, ds in _datasets().items()}


def test_flags_are_cf_and_decode_with_cf_xarray(datasets):
    from cf_xarray.units import units  # noqa: F401  (pint with UDUNITS names)
    for name, ds in datasets.items():
        assert ds.attrs["Conventions"].startswith("CF-")
        nflags = 0
        for k, v in ds.variables.items():
            assert "legend" not in v.attrs, (name, k)
            vals = v.attrs.get("flag_values", v.attrs.get("flag_masks"))
            if vals is None:
                continue
            nflags += 1
            words = v.attrs["flag_meanings"].split()
            assert len(np.atleast_1d(vals)) == len(words), (name, k)
            assert np.asarray(vals).dtype == v.dtype, (name, k)
        assert nflags >= 1, name
        assert "status" in ds.variables or name == "simulate"
    sim = datasets["simulate"]
    # flag decoding by meaning (cf_xarray): the region at t, the visited bit mask
    assert bool((sim.region.cf == "Gamma_minus").any())
    assert bool(sim.visited.cf.isin(["Gamma_plus"]).any())
    bif = datasets["bifurcation"]
    assert bool((bif.sweep.cf == "up")[0]) and bool((bif.sweep.cf == "down")[1])
    assert bool((bif.status.cf == "ok").all())


def test_units_parse_as_udunits(datasets):
    from cf_xarray.units import units
    for name, ds in datasets.items():
        for k, v in ds.variables.items():
            u = v.attrs.get("units")
            if u is not None and u != "1":  # "1": dimensionless
                units.parse_units(u)  # raises on a unit that UDUNITS / pint do not know
                assert u != "T", (name, k)


def test_results_are_variables_and_swept_parameters_are_not_attrs(datasets):
    poi = datasets["poincare"]
    for k in ("period", "max_X", "min_X", "contact", "transient_used"):
        assert k in poi.variables and k not in poi.attrs
    assert "t_section" in poi.coords and "t_n" not in poi.coords
    eta = datasets["eta_study"]
    for k in ("orbit_X", "orbit_V", "orbit_region", "exact_orbit_X", "recommended_eta"):
        assert k in eta.variables
    assert not any(k.startswith("portrait") for k in eta.variables)
    assert "param_eta" not in eta.attrs and "t_section" in eta.coords
    assert "param_omega" not in datasets["bifurcation"].attrs
    assert "param_omega" not in datasets["resonance"].attrs
    # two poincare sections concatenate without copying attrs back
    import xarray as xr
    both = xr.concat([poi, poi], dim="run")
    assert both.period.shape == (2,)
