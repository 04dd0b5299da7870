"""A Python function as a retrieval: given the Rrs in memory, scored like the same algorithm run
as an external program on the same Rrs, its failures reported, and nothing lent across."""

import importlib.util
import warnings

import numpy as np
import pytest

xr = pytest.importorskip("xarray", reason="xarray is not installed")
pytest.importorskip("netCDF4", reason="netCDF4 (the external program's NetCDF backend) is not installed")
pd = pytest.importorskip("pandas", reason="pandas is not installed")
shoal = pytest.importorskip("shoal", reason="the shoal package is not installed: pip install ./python")

from conftest import DECIMATION, REPO, has_program_python  # noqa: E402


def builtin_oc4():
    """presets/examples/oc4.py, the program the built-in study `lake_hume_oc4` runs."""
    spec = importlib.util.spec_from_file_location("oc4", REPO / "presets" / "examples" / "oc4.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_function_scores_as_the_same_program(tmp_path):
    if not has_program_python():
        pytest.skip("the program path needs python3 with xarray and netCDF4 on PATH")
    oc4 = builtin_oc4()
    program = shoal.study("lake_hume_oc4", decimation=DECIMATION, allow_external=True)
    # The same study with the program replaced by the same code, registered in this process and
    # named by the study file.
    text = (REPO / "presets" / "studies" / "lake_hume_oc4.ron").read_text()
    start = text.index('command: ["python3"')
    end = text.index("\n", start)
    (tmp_path / "oc4_function.ron").write_text(text[:start] + 'function: Some("oc4_here"),' + text[end:])

    def chlorophyll(ds):
        chl = oc4.chlorophyll(ds)
        return np.where(chl == oc4.FILL, np.nan, chl)

    shoal.register_retrieval("oc4_here", chlorophyll)
    try:
        here = shoal.study(str(tmp_path / "oc4_function.ron"), decimation=DECIMATION)
    finally:
        shoal.unregister_retrieval("oc4_here")
    pd.testing.assert_frame_equal(here.metrics, program.metrics)
    rows = here.metrics[here.metrics["product"] == "oc4"]
    assert len(rows) == 2 and rows["n"].min() > 100
    for label in ("cubesat", "smallsat"):
        a, b = here.datasets[label].oc4_chl_mg_m3.values, program.datasets[label].oc4_chl_mg_m3.values
        assert np.array_equal(a, b, equal_nan=True)


def test_a_function_gets_what_a_program_reads():
    seen = {}

    def keep(ds):
        seen["ds"] = ds
        return np.full(ds.rrs.shape[:2], 1.0)

    ds = shoal.simulate("lake_hume_bloom", "cubesat", decimation=16,
                        retrievals=[shoal.Retrieval("keep", keep, ["chl_mg_m3"])])
    given = seen["ds"]
    assert {"rrs", "wavelength", "bandwidth", "band_name", "nedr", "surface_class",
            "solar_zenith_angle", "sensor_zenith_angle"} <= set(given.variables)
    assert not any(name.startswith("true") for name in given.variables)
    water = ds.surface_class.values == 0
    assert np.array_equal(np.isnan(given.rrs.values).all(axis=2), ~water | np.isnan(ds.rrs.values).all(axis=2))
    assert np.all(ds.keep_chl_mg_m3.values[water] == 1.0)


def test_an_array_a_function_returned_is_copied_not_lent():
    kept = []

    def reuses(ds):
        # The second run's call overwrites the array the first run's call returned: were it lent
        # to Shoal instead of copied, the first run's product would change with it.
        for earlier in kept:
            earlier[...] = 5.0
        kept.append(np.full(ds.rrs.shape[:2], 1.0))
        return kept[-1]

    study = shoal.study("cubesat_vs_smallsat", decimation=16, retrievals=[shoal.Retrieval("reuses", reuses, ["chl_mg_m3"])])
    assert len(kept) == 2 and np.all(kept[0] == 5.0)
    for label in ("cubesat", "smallsat"):
        product = study.datasets[label].reuses_chl_mg_m3.values
        returned = np.isfinite(product)
        assert returned.any() and np.all(product[returned] == 1.0), label


def test_a_failing_function_is_reported_and_the_run_kept():
    def broken(ds):
        raise ZeroDivisionError("no bands today")

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        study = shoal.study("cubesat_vs_smallsat", decimation=16, retrievals=[shoal.Retrieval("broken", broken, ["chl_mg_m3"])])
    messages = [str(w.message) for w in caught]
    assert any("broken" in m and "no bands today" in m for m in messages), messages
    assert "no bands today" in study.failures["cubesat"][0][1]
    # The other retrieval's products are all there; the broken one returned nothing.
    assert np.isfinite(study.datasets["cubesat"].alm_chl_mg_m3.values).any()
    assert np.isnan(study.datasets["cubesat"].broken_chl_mg_m3.values).all()


def test_a_function_of_the_wrong_shape_is_an_error_naming_it():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        shoal.simulate("lake_hume_bloom", "cubesat", decimation=16,
                       retrievals=[shoal.Retrieval("small", lambda ds: np.ones((3, 3)), ["chl_mg_m3"])])
    assert any("3 × 3" in str(w.message) for w in caught), [str(w.message) for w in caught]
