"""Shoal from Python: run studies and simulations in-process and get xarray datasets.

    import shoal
    study = shoal.study("cubesat_vs_smallsat", decimation=4)
    study.metrics                      # pandas DataFrame: metrics.csv
    study.datasets["smallsat"]         # xarray Dataset: products.nc of `--format netcdf`

Each dataset holds the same variables, coordinates, CF attributes and values as the NetCDF file
`shoal study ... --format netcdf` writes: the engine hands over the file's contents in memory and
xarray decodes them with the same CF decoding `xarray.open_dataset` applies to the file.

A Python function can be a retrieval (`Retrieval`): Shoal gives it the corrected Rrs as the
xarray dataset an external retrieval program reads from its input file, and scores what it
returns like any retrieval. The engine runs with the GIL released; Ctrl-C cancels a run.
"""

from __future__ import annotations

import io
import warnings
from dataclasses import dataclass
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from . import _native
from ._native import InputError, RunError

__version__ = _native.__version__
__all__ = [
    "InputError",
    "Retrieval",
    "RunError",
    "Study",
    "preset",
    "presets",
    "ranges",
    "register_retrieval",
    "simulate",
    "study",
    "unregister_retrieval",
]


def presets() -> dict[str, list[str]]:
    """The built-in presets by kind: ``{"study": [...], "scene": [...], "instrument": [...]}``."""
    return _native.presets()


def preset(kind: str, name: str) -> dict[str, Any]:
    """A preset's fields as a dict (``kind``: ``"study"``, ``"scene"`` or ``"instrument"``;
    ``name``: a built-in, your library's or a RON file): ``preset("instrument", "cubesat")["aperture_mm"]``.
    The paths ``settings=`` takes are these fields' (``instrument.aperture_mm``)."""
    import json

    return json.loads(_native.preset(kind, name))


def ranges() -> list[dict[str, Any]]:
    """Every numeric field's allowed values (``shoal ranges``): dicts with ``path``, ``lo``,
    ``hi``, ``lo_open``, ``hi_open``, ``unit``, ``whole``, ``meaning`` and ``allowed``."""
    return _native.ranges()


# --- data sets -------------------------------------------------------------------------------


def _attr(value):
    """An attribute as the netCDF4 backend gives it: text as ``str``, numbers as a NumPy array
    (one number as a NumPy scalar)."""
    if isinstance(value, str):
        return value
    dtype, numbers = value
    array = np.array(numbers, dtype=dtype)
    return array[0] if array.size == 1 else array


def _raw_dataset(raw):
    """The file's contents before CF decoding, as a backend hands them to xarray."""
    import xarray as xr

    sizes = dict(raw["dims"])
    variables = {}
    for name, dims, attrs, dtype, data in raw["variables"]:
        values = np.frombuffer(data, dtype=np.dtype(dtype)).reshape(tuple(sizes[d] for d in dims))
        variables[name] = xr.Variable(dims, values, {k: _attr(v) for k, v in attrs})
    return xr.Dataset(variables, attrs={k: _attr(v) for k, v in raw["attrs"]})


def _dataset(raw):
    """The engine's data set as xarray decodes the same file (fill values to NaN, the
    ``coordinates`` attributes to coordinates, characters to strings)."""
    import xarray as xr

    return xr.decode_cf(_raw_dataset(raw))


def _products(raw):
    """A run's products. The bands stay coordinates without the cubes (``cubes=False``), whose
    ``coordinates`` attributes made them so in the file."""
    ds = _dataset(raw)
    bands = [name for name in ("wavelength", "bandwidth", "band_name") if name in ds.data_vars]
    return ds.set_coords(bands) if bands else ds


# --- retrievals written in Python ---------------------------------------------------------------


@dataclass
class Retrieval:
    """A Python function as a retrieval of a study.

    ``function(ds)`` gets the xarray dataset an external retrieval program reads (``rrs`` with
    dimensions line, pixel, band and NaN where the correction flagged it or off water;
    ``wavelength``, ``bandwidth``, ``band_name``, ``nedr``, ``surface_class``, the sun and view
    zenith angles) and returns each of ``products`` (Shoal's names: ``chl_mg_m3``, ``nap_g_m3``,
    ``cdom_per_m``, ``depth_m``) as a (line, pixel) array: a dict, an xarray Dataset, or, for one
    product, the array itself. NaN, a non-positive value or a ``_FillValue`` means not returned.
    """

    name: str
    function: Callable[[Any], Any]
    products: Sequence[str]
    bands: Sequence[str] | None = None


def _values(item):
    """A product's values as float64, NaN where its ``_FillValue`` (if it has one) is."""
    fill = None
    if hasattr(item, "encoding") and hasattr(item, "values"):
        fill = item.encoding.get("_FillValue", item.attrs.get("_FillValue"))
        item = item.values
    values = np.array(item, dtype=np.float64)
    if fill is not None:
        values[values == fill] = np.nan
    return values


def _bridge(function):
    """The callable the engine calls: its input as a dataset in, each product as
    ``(float64 bytes, shape)`` out (copies both ways)."""

    def call(raw):
        result = function(_dataset(raw))
        if hasattr(result, "data_vars"):
            result = {name: result[name] for name in result.data_vars}
        elif not isinstance(result, Mapping):
            wanted = dict(raw["attrs"]).get("products_wanted", "").split()
            if len(wanted) != 1:
                raise TypeError("return a dict of products (this retrieval makes several)")
            result = {wanted[0]: result}
        out = {}
        for name, item in result.items():
            values = _values(item)
            if values.ndim != 2:
                raise ValueError(f"`{name}` has {values.ndim} dimensions; a product is (line, pixel)")
            out[str(name)] = (np.ascontiguousarray(values, dtype="<f8").tobytes(), values.shape)
        return out

    return call


def register_retrieval(name: str, function: Callable[[Any], Any]) -> None:
    """Register ``function`` (see `Retrieval`) as ``name``, for study files that name it:
    ``External((name: "oc4", function: Some("oc4"), products: ["chl_mg_m3"]))``."""
    _native.register_retrieval(name, _bridge(function))


def unregister_retrieval(name: str) -> None:
    """Forget the function registered as ``name``."""
    _native.unregister_retrieval(name)


# --- runs ---------------------------------------------------------------------------------------


def _settings(settings):
    if settings is None:
        return None
    if not isinstance(settings, Mapping):
        raise TypeError("settings: a dict of field path -> number, e.g. {'instrument.aperture_mm': 80}")
    return [(str(k), float(v)) for k, v in settings.items()]


def _register(retrievals):
    """Register each `Retrieval`'s function for one call: (name, key, products, bands) each."""
    extra = []
    for r in retrievals:
        if not isinstance(r, Retrieval):
            raise TypeError(f"retrievals: {r!r} is not a shoal.Retrieval")
        key = f"python.{r.name}.{id(r.function):x}"
        _native.register_retrieval(key, _bridge(r.function))
        extra.append((r.name, key, list(r.products), None if r.bands is None else list(r.bands)))
    return extra


def _unregister(extra):
    for _, key, _, _ in extra:
        _native.unregister_retrieval(key)


def _warn_failures(label, failures):
    for retrieval, message in failures:
        warnings.warn(f"{label}: the retrieval `{retrieval}` returned nothing: {message}", RuntimeWarning, stacklevel=3)


@dataclass
class Study:
    """A study's results: ``datasets`` by run (the CLI's folder names: the instrument's label,
    ``label_seedN`` with several seeds), ``metrics`` (metrics.csv), each run's configuration as
    RON (``configs``) and what a retrieval said when it returned nothing (``failures``)."""

    name: str
    description: str
    datasets: dict[str, Any]
    metrics: Any
    configs: dict[str, str]
    failures: dict[str, list[tuple[str, str]]]


def study(
    study: str | None = None,
    *,
    decimation: int | None = None,
    seeds: Sequence[int] | None = None,
    settings: Mapping[str, float] | None = None,
    retrievals: Sequence[Retrieval] = (),
    threads: int = 0,
    allow_external: bool = False,
    progress: Callable[[float], Any] | None = None,
    cubes: bool = True,
) -> Study:
    """Run a study: a built-in name, a preset of your library, or a RON file (``None``: the
    default study, as ``shoal study``).

    - ``decimation``: simulate every n-th line and detector; ``seeds``: the noise seeds.
    - ``settings``: numeric fields set on every run by path, as a sweep sets them
      (``{"instrument.aperture_mm": 80}``); validated like any configuration.
    - ``retrievals``: `Retrieval` functions added to the study's retrievals.
    - ``allow_external``: run the external programs the study names (nothing runs otherwise).
    - ``progress(fraction)``: called about ten times a second while the study runs.
    - ``cubes=False``: leave out the four (line, pixel, band) variables (Level-1, Rrs, its flags,
      the true Rrs); the engine then streams them instead of keeping them, which for a
      full-resolution study is several times faster and smaller (for sweeps).
    """
    import pandas as pd

    extra = _register(retrievals)
    try:
        out = _native.study(
            study,
            decimation=decimation,
            seeds=None if seeds is None else [int(s) for s in seeds],
            threads=int(threads),
            settings=_settings(settings),
            functions=extra,
            allow_external=bool(allow_external),
            progress=progress,
            cubes=bool(cubes),
        )
    finally:
        _unregister(extra)
    several_seeds = len({seed for _, seed, _, _, _ in out["runs"]}) > 1
    datasets, configs, failures = {}, {}, {}
    for label, seed, raw, failed, config in out["runs"]:
        key = f"{label}_seed{seed}" if several_seeds else label
        datasets[key] = _products(raw)
        configs[key] = config
        failures[key] = failed
        _warn_failures(key, failed)
    metrics = pd.read_csv(io.StringIO(out["metrics_csv"]))
    return Study(out["name"], out["description"], datasets, metrics, configs, failures)


def simulate(
    scene: str = "lake_hume_bloom",
    instrument: str = "nominal",
    *,
    config: str | None = None,
    decimation: int | None = None,
    seed: int | None = None,
    noise: bool = True,
    quantise: bool = True,
    diffuser_bias_pct: float | None = None,
    gain_drift_pct: float | None = None,
    approximate_correction: bool = False,
    settings: Mapping[str, float] | None = None,
    retrievals: Sequence[Retrieval] = (),
    threads: int = 0,
    allow_external: bool = False,
    progress: Callable[[float], Any] | None = None,
    cubes: bool = True,
):
    """Fly ``instrument`` over ``scene`` (preset names or RON files; ``config``: a whole run
    configuration) as ``shoal simulate`` does, and return the products as an xarray Dataset:
    the file ``shoal simulate --format netcdf`` writes. ``settings``, ``retrievals`` and
    ``cubes`` as in `study` (a simulation runs no retrieval unless given one)."""
    argv = ["--scene", str(scene), "--instrument", str(instrument)]
    if config is not None:
        argv += ["--config", str(config)]
    for flag, value in (
        ("--decimation", decimation),
        ("--seed", seed),
        ("--diffuser-bias-pct", diffuser_bias_pct),
        ("--gain-drift-pct", gain_drift_pct),
    ):
        if value is not None:
            argv += [flag, str(value)]
    if not noise:
        argv.append("--no-noise")
    if not quantise:
        argv.append("--no-quantise")
    if approximate_correction:
        argv.append("--approximate-correction")
    extra = _register(retrievals)
    try:
        out = _native.simulate(
            argv,
            settings=_settings(settings),
            functions=extra,
            threads=int(threads),
            allow_external=bool(allow_external),
            progress=progress,
            cubes=bool(cubes),
        )
    finally:
        _unregister(extra)
    _warn_failures(f"{instrument} over {scene}", out["failures"])
    return _products(out["dataset"])
