#!/usr/bin/env python3
"""NASA's OC4 band-ratio chlorophyll on a Shoal NetCDF product: an example of a scientist's own
algorithm run outside Shoal and scored by `shoal score`.

    shoal study cubesat_vs_smallsat --format netcdf --out results/study
    python3 presets/examples/oc4.py results/study/cubesat/products.nc oc4_cubesat.nc
    shoal score oc4_cubesat.nc --truth results/study/cubesat

OC4 (O'Reilly et al. 1998, J. Geophys. Res. 103, 24937-24953) with the OC4v6 coefficients of
NASA's 2010 reprocessing: log10(chl) = a0 + a1 x + a2 x^2 + a3 x^3 + a4 x^4, where
x = log10(max(Rrs443, Rrs490, Rrs510) / Rrs555). The product's bands nearest 443, 490, 510 and
555 nm are used (within 15 nm). OC4 is an open-ocean algorithm: over a turbid reservoir it is
expected to fail, which is what scoring it shows.

The same function, `chlorophyll(ds)`, runs in-process as a Python retrieval (the `shoal` Python
package: python/examples/sweep_and_oc4.py).

Reads `rrs` and its `wavelength` coordinate; writes `chl_mg_m3` (line, pixel) with a fill value
where a ratio is not positive or a band is missing. Needs xarray with a NetCDF backend
(Debian: python3-xarray python3-netcdf4).
"""
import sys

import numpy as np
import xarray as xr

OC4V6 = [0.3272, -2.9940, 2.7218, -1.2259, -0.5683]
FILL = -9999.0


def nearest(wavelengths, target, tolerance=15.0):
    i = int(np.argmin(np.abs(wavelengths - target)))
    if abs(wavelengths[i] - target) > tolerance:
        sys.exit(f"oc4.py: no band within {tolerance} nm of {target} nm")
    return i


def chlorophyll(ds):
    """OC4v6 chlorophyll-a (mg m-3) of a dataset with `rrs` (line, pixel, band) and its
    `wavelength`; FILL where a ratio is not positive or not finite."""
    wl = ds.wavelength.values
    rrs = ds.rrs
    blue = np.stack([rrs.isel(band=nearest(wl, w)).values for w in (443.0, 490.0, 510.0)])
    green = rrs.isel(band=nearest(wl, 555.0)).values
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.nanmax(blue, axis=0) / green
        x = np.log10(ratio)
        chl = 10.0 ** np.polyval(OC4V6[::-1], x)
    return np.where(np.isfinite(chl) & (ratio > 0), chl, FILL).astype("float32")


def main(src, dst):
    ds = xr.open_dataset(src)
    chl = chlorophyll(ds)
    out = xr.Dataset(
        {"chl_mg_m3": (("line", "pixel"), chl, {"units": "mg m-3", "long_name": "OC4v6 chlorophyll-a"})},
        attrs={"source": "presets/examples/oc4.py (OC4v6, O'Reilly et al. 1998)", "input": str(src)},
    )
    out.chl_mg_m3.encoding["_FillValue"] = FILL
    out.to_netcdf(dst, format="NETCDF3_64BIT")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: oc4.py PRODUCTS.nc OUT.nc")
    main(sys.argv[1], sys.argv[2])
