"""The datasets are the NetCDF files the command line writes: same variables, coordinates, CF
attributes and values (xarray's assert_identical compares values exactly, NaN equal to NaN)."""

import numpy as np
import pytest

xr = pytest.importorskip("xarray", reason="xarray is not installed")
pytest.importorskip("netCDF4", reason="netCDF4 (the NetCDF backend the comparison reads with) is not installed")
pd = pytest.importorskip("pandas", reason="pandas is not installed")
shoal = pytest.importorskip("shoal", reason="the shoal package is not installed: pip install ./python")

from conftest import DECIMATION, run_cli  # noqa: E402


def assert_same_bits(a, b):
    """Identical datasets, and every float variable's bits equal (assert_identical compares by value)."""
    xr.testing.assert_identical(a, b)
    for name in b.variables:
        x, y = np.asarray(a[name].values), np.asarray(b[name].values)
        assert x.dtype == y.dtype, name
        if x.dtype.kind == "f":
            assert np.array_equal(x.view(np.uint32), y.view(np.uint32)), name


def test_simulate_is_the_netcdf_file(tmp_path):
    run_cli("simulate", "--scene", "lake_hume_bloom", "--instrument", "cubesat", "--decimation", str(DECIMATION),
            "--format", "netcdf", "--out", str(tmp_path / "run"))
    with xr.open_dataset(tmp_path / "run" / "products.nc") as file:
        ds = shoal.simulate("lake_hume_bloom", "cubesat", decimation=DECIMATION)
        assert_same_bits(ds, file.load())
    # The CF metadata arrived: a standard name, a fill value decoded to NaN off water, the bands.
    assert ds.rrs.attrs["standard_name"].startswith("surface_ratio_of_upwelling_radiance")
    assert ds.rrs.encoding["_FillValue"] == np.float32(-9999.0)
    assert list(ds.band_name.values[:2]) == [b"Oa01", b"Oa02"]
    assert set(ds.coords) >= {"x", "y", "wavelength", "bandwidth", "band_name"}
    with xr.open_dataset(tmp_path / "run" / "products.nc", mask_and_scale=False) as raw:
        for name in ("rrs", "true_rrs", "true_chl_mg_m3", "level1_radiance"):
            assert np.array_equal(np.isnan(ds[name].values), raw[name].values == -9999.0), name


def test_study_is_the_netcdf_files_and_the_metrics_table(tmp_path):
    out = tmp_path / "study"
    run_cli("study", "cubesat_vs_smallsat", "--decimation", str(DECIMATION), "--format", "netcdf",
            "--no-figures", "--out", str(out))
    study = shoal.study("cubesat_vs_smallsat", decimation=DECIMATION)
    assert study.name == "cubesat_vs_smallsat"
    assert sorted(study.datasets) == ["cubesat", "smallsat"]
    for label, ds in study.datasets.items():
        with xr.open_dataset(out / label / "products.nc") as file:
            assert_same_bits(ds, file.load())
    pd.testing.assert_frame_equal(study.metrics, pd.read_csv(out / "metrics.csv"))
    # Not returned is NaN where the file holds its fill value.
    with xr.open_dataset(out / "cubesat" / "products.nc", mask_and_scale=False) as raw:
        filled = raw.alm_chl_mg_m3.values == -9999.0
    assert np.array_equal(np.isnan(study.datasets["cubesat"].alm_chl_mg_m3.values), filled)
    chl = study.metrics[(study.metrics["variable"] == "chl_mg_m3")]
    assert len(chl) == 2 and (chl["mae_pct"] > 0).all()
    # Without cubes: the lean engine, the same file less its four cubes, the same metrics.
    lean = shoal.study("cubesat_vs_smallsat", decimation=DECIMATION, cubes=False)
    cubes = ["level1_radiance", "rrs", "rrs_flags", "true_rrs"]
    for label, ds in lean.datasets.items():
        with xr.open_dataset(out / label / "products.nc") as file:
            assert_same_bits(ds, file.load().drop_vars(cubes))
    pd.testing.assert_frame_equal(lean.metrics, study.metrics)
    assert "StudySpec" not in study.configs["cubesat"] and study.configs["cubesat"].startswith("RunConfig(")


def test_settings_and_seeds_are_the_sweeps():
    base = shoal.simulate("lake_hume_bloom", "cubesat", decimation=16)
    bigger = shoal.simulate("lake_hume_bloom", "cubesat", decimation=16, settings={"instrument.aperture_mm": 200})
    assert "aperture_mm: 200.0" in bigger.attrs["shoal_configuration"]
    # A larger aperture collects more light: the same scene, less noise in Rrs.
    noise = lambda ds: float(np.nanmedian(np.abs(ds.rrs - ds.true_rrs)))  # noqa: E731
    assert noise(bigger) < noise(base)
    two = shoal.study("cubesat_vs_smallsat", decimation=16, seeds=[1, 2])
    assert sorted(two.datasets) == ["cubesat_seed1", "cubesat_seed2", "smallsat_seed1", "smallsat_seed2"]
    assert sorted(two.metrics["seed"].unique()) == [1, 2]


def test_presets_and_ranges():
    p = shoal.presets()
    assert "cubesat_vs_smallsat" in p["study"] and "cubesat" in p["instrument"] and "lake_hume_bloom" in p["scene"]
    aperture = next(r for r in shoal.ranges() if r["path"] == "instrument.aperture_mm")
    assert aperture["unit"] == "mm" and aperture["lo"] < 60 < aperture["hi"]


def test_a_preset_is_its_fields():
    cubesat = shoal.preset("instrument", "cubesat")
    assert cubesat["name"] == "cubesat" and cubesat["aperture_mm"] > 0
    assert shoal.preset("study", "cubesat_vs_smallsat")["name"] == "cubesat_vs_smallsat"
    with pytest.raises(shoal.InputError, match="allowed: study, scene, instrument") as e:
        shoal.preset("mission", "cubesat")
    assert e.value.field == "kind"
