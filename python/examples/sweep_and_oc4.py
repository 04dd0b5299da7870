#!/usr/bin/env python3
"""Shoal from Python, as a notebook would use it: a sweep of the CubeSat's aperture, and NASA's OC4
chlorophyll written in Python as a retrieval scored beside Shoal's own aLMI.

    pip install ./python            # from the repository's root
    python3 python/examples/sweep_and_oc4.py [DECIMATION]

The tests run it (python/tests/test_example.py) at a coarse decimation.
"""

import sys

import numpy as np

import shoal

# OC4v6 (O'Reilly et al. 1998, J. Geophys. Res. 103, 24937-24953; NASA's 2010 coefficients):
# log10(chl) = a0 + a1 x + ... + a4 x^4, x = log10(max(Rrs443, Rrs490, Rrs510) / Rrs555).
OC4V6 = [0.3272, -2.9940, 2.7218, -1.2259, -0.5683]


def oc4(ds):
    """Chlorophyll-a (mg m-3) from the bands nearest 443, 490, 510 and 555 nm; NaN where the
    ratio is not positive."""
    wl = ds.wavelength.values

    def band(target):
        return ds.rrs.isel(band=int(np.argmin(np.abs(wl - target)))).values

    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.nanmax(np.stack([band(443.0), band(490.0), band(510.0)]), axis=0) / band(555.0)
        chl = 10.0 ** np.polyval(OC4V6[::-1], np.log10(ratio))
    return np.where(ratio > 0, chl, np.nan)


def log_mae_pct(retrieved, truth):
    """The paper's log-space mean absolute error, %: 100 (10^mean|log10 r - log10 t| - 1)."""
    ok = np.isfinite(retrieved) & np.isfinite(truth) & (retrieved > 0) & (truth > 0)
    return 100.0 * (10.0 ** np.mean(np.abs(np.log10(retrieved[ok]) - np.log10(truth[ok]))) - 1.0)


def main(decimation=4):
    print(f"Shoal {shoal.__version__}: decimation {decimation}")

    # 1. OC4 in Python beside aLMI, on the CubeSat and the SmallSat over the Lake Hume bloom.
    study = shoal.study(
        "cubesat_vs_smallsat",
        decimation=decimation,
        retrievals=[shoal.Retrieval("oc4", oc4, ["chl_mg_m3"])],
    )
    chl = study.metrics[study.metrics.variable == "chl_mg_m3"]
    print("\nchl-a over the Lake Hume bloom (metrics.csv):")
    print(chl[["instrument", "product", "mae_pct", "bias_pct", "returned_pct"]].to_string(index=False))

    # 2. A sweep of the CubeSat's aperture: each run's products as an xarray dataset, with OC4
    #    run in-process as the run's retrieval and scored against the truth here, in Python.
    print("\nCubeSat aperture sweep over the Lake Hume bloom, OC4 chl-a:")
    print(" aperture_mm  OC4 MAE %  |Rrs(443) error|, median (sr-1)")
    for aperture_mm in (40.0, 60.0, 90.0, 135.0):
        ds = shoal.simulate(
            "lake_hume_bloom",
            "cubesat",
            decimation=decimation,
            settings={"instrument.aperture_mm": aperture_mm},
            retrievals=[shoal.Retrieval("oc4", oc4, ["chl_mg_m3"])],
        )
        mae = log_mae_pct(ds.oc4_chl_mg_m3.values, ds.true_chl_mg_m3.values)
        blue = int(np.argmin(np.abs(ds.wavelength.values - 443.0)))
        error = float(np.nanmedian(np.abs(ds.rrs.isel(band=blue) - ds.true_rrs.isel(band=blue))))
        print(f" {aperture_mm:11.0f}  {mae:9.1f}  {error:.2e}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 4)
