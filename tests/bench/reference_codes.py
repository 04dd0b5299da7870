#!/usr/bin/env python3
"""Re-measure the Python reference codes side by side with `shoal bench`, one core each.

    python3 tests/bench/reference_codes.py --sambuca-core PATH --sambuca PATH --dea PATH \
        --shoal target/release/shoal --rounds 8 --core 1

Each PATH is a checkout of a public reference code (leave one out and its rows are skipped, with
the reason). Their code is imported from the checkouts, never copied; the inputs are the
project's reference data in tests/data/. Python >= 3.10 with numpy and scipy (see README.md).

Method (the reviewer's): every measurement is its own process on one core (`taskset -c CORE`,
else sched_setaffinity), BLAS threads 1. A round runs the reference forward workloads, then
`shoal bench --only water`, then the reference retrieval workloads, then `shoal bench --only
retrieval`, and pairs each Shoal row with the reference rate of the same round. Printed: per-round
ratios, their median and min-max, and a warning when a ratio is more than 6 % from its median or
the 1-minute load exceeds 1.1 (reviewer: AMD EPYC, 8 rounds, load <= 1.1, every ratio within 6 %).

Reference workloads: the same calls, pixels and configuration every round (counts x --scale).
- forward_shallow: sambuca_core.forward_model, 30 000 calls, 350-800 nm at 1 nm (451 values),
  SAMBUCA's SIOPs and constants (tests/data/sambuca_forward, case `base`): chl 1.0 + 0.1 (i mod 7),
  cdom 0.05, nap 2, depth 5 + (i mod 5) m, 50/50 NCC_3subs sand / brown Acropora, sun 30 deg, nadir.
- forward_deep: the same with depth = inf. The code has no deep-only path: its rrs is then its
  rrsdp, at the cost of a shallow call. Shoal's deep row is divided by this, not by the shallow.
- almi: DEA `chunkProcessLMI`, 40 calls on one chunk of the 296 pixels of
  tests/data/retrieval_reference/almi that pass DEA's screen (11 840 pixels): 8 monochromatic
  OLCI bands, Shoal's almi_1..8 SIOP sets, RMSE cost, minValidConc 1e-5 (almi_config.ini).
- slsqp28: `sambuca.minimize` (SciPy SLSQP over all 3 pairs of HI_3 Acropora / sand / Turf Algae),
  CASI04 bands 1-28 over the 451 values, flat NEDR 5e-4, p0 = (max - min)/2, set-up
  CASI28_HI3_wide: every third of its 90 stored pixels (ids 0, 3, ..., 87), once.
- slsqp4: the same for set-up ALOS4_MB_notebook (ALOS bands 1-4, one pair: Moreton Bay white
  sand / brown mud, the notebook's NEDR and bounds): its 40 stored pixels, twice (80 fits).

What Shoal's rows time instead, and how the workloads differ: tests/bench/README.md ("The
workloads") and the footnote `shoal bench` prints under each table.

With --shoal-before OLD, an earlier build runs right after --shoal in every round: each table then
also pairs OLD's rows with the same round's reference and gives new / old per round (a kernel
change measured against the reference codes and against its own past in the same rounds).
"""
from __future__ import annotations

import argparse
import ast
import configparser
import csv
import datetime
import importlib
import json
import math
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import time
import types
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
DATA = REPO / "tests" / "data"
EXPECTED = {"sambuca_core": "64483a0", "sambuca": "d153684", "dea": "dd794b0"}
MARKER = {"sambuca_core": "sambuca_core/forward_model.py", "sambuca": "sambuca/minimize_wrapper.py",
          "dea": "Python-aLMI-X/chunkProcessLMI.py"}
BLAS_ONE = {v: "1" for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
LOAD_LIMIT, SPREAD_LIMIT = 1.1, 0.06
RATE_HEADERS = ("evaluations/s", "pixels/s per core (noisy pixels)")

# Reference workloads: key -> (checkouts needed, Shoal section, what, unit, count, reviewer figure).
WORKLOADS = {
    "forward_shallow": (("sambuca_core",), "water", "forward 451 λ, shallow, Rrs only, f64", "calls/s", 30_000, 23_973),
    "forward_deep": (("sambuca_core",), "water", "forward 451 λ, deep, f64", "deep calls/s", 30_000, 21_888),
    "almi": (("dea",), "retrieval", "aLMI 8 bands, 8 SIOP sets", "px/s", 40, 8_209),
    "slsqp28": (("sambuca", "sambuca_core"), "retrieval", "SLSQP 28 bands, 3 substrate pairs", "px/s", 30, 18.2),
    "slsqp4": (("sambuca", "sambuca_core"), "retrieval", "SLSQP 4 bands, 1 pair", "px/s", 80, 47.6),
}
REF_MODE = ", reference mode (SLSQP from (max − min)/2)"
# (reference workload, Shoal row label as printed by src/cli/bench.rs / bench_retrieval.rs,
#  constant in src/cli/bench_reference.rs that `shoal bench` divides that row by).
PAIRS = [
    ("forward_shallow", "shallow, Rrs only (per-pixel path)", "SAMBUCA_FORWARD"),
    ("forward_deep", "optically deep, Rrs only", "SAMBUCA_FORWARD_DEEP"),
    ("almi", "aLMI, 8 SIOP sets, noise-weighted", "DEA_ALMI"),
    ("almi", "aLMI, 8 SIOP sets, unweighted (as DEA)", "DEA_ALMI"),
    ("slsqp28", "SAMBUCA-style, 3 substrate pairs", "SAMBUCA_FIT_28"),
    ("slsqp28", "SAMBUCA-style, 3 substrate pairs" + REF_MODE, "SAMBUCA_FIT_28"),
    ("slsqp4", "SAMBUCA-style, 1 substrate pair", "SAMBUCA_FIT_4"),
    ("slsqp4", "SAMBUCA-style, 1 substrate pair" + REF_MODE, "SAMBUCA_FIT_4"),
]


# ---------------------------------------------------------------- worker side (one process each)

def stub_io_modules(names: list[str]) -> list[str]:
    """Put empty modules in place of file-I/O imports that are missing (pandas, xlrd, spectral,
    netCDF4): the reference codes import them at load time but never on the timed paths."""
    stubbed = []
    for name in names:
        try:
            importlib.import_module(name)
        except ImportError:
            parts = name.split(".")
            for i in range(1, len(parts) + 1):
                sub = ".".join(parts[:i])
                if sub not in sys.modules:
                    sys.modules[sub] = types.ModuleType(sub)
                    sys.modules[sub].__getattr__ = placeholder  # e.g. netCDF4.Dataset, read at import
                    if i > 1:
                        setattr(sys.modules[".".join(parts[: i - 1])], parts[i - 1], sys.modules[sub])
            stubbed.append(name)
    return stubbed


def placeholder(name: str):
    if name.startswith("__"):
        raise AttributeError(name)
    return type(name, (), {})


def import_sambuca_core(path: str):
    stubbed = stub_io_modules(["pandas", "xlrd", "spectral.io.envi", "spectral.io.spyfile"])
    sys.path.insert(0, path)
    import sambuca_core
    return sambuca_core, stubbed


def read_columns(path: Path, where=None) -> dict[str, list[str]]:
    with open(path, newline="") as f:
        rows = [r for r in csv.DictReader(f) if where is None or where(r)]
    return {k: [r[k] for r in rows] for k in (rows[0] if rows else {})}


def forward_workload(args, deep: bool):
    import numpy as np
    sbc, stubbed = import_sambuca_core(args.sambuca_core)
    col = read_columns(DATA / "sambuca_forward" / "inputs_1nm.csv")
    spec = {k: np.array(v, dtype=float) for k, v in col.items()}
    base = read_columns(DATA / "sambuca_forward" / "cases.csv", lambda r: r["case_id"] == "base")
    names = ("a_cdom_slope a_nap_slope bb_ph_slope lambda0cdom lambda0nap lambda0x x_ph_lambda0x x_nap_lambda0x "
             "a_cdom_lambda0cdom a_nap_lambda0nap bb_lambda_ref water_refractive_index theta_air off_nadir q_factor")
    const = {k: float(base[k][0]) for k in names.split()}
    const["bb_nap_slope"] = float(base["bb_nap_slope"][0]) if base["bb_nap_slope"][0] else None
    wl, n_bands = spec["wavelength_nm"], len(spec["wavelength_nm"])

    def call(i: int):
        return sbc.forward_model(1.0 + (i % 7) * 0.1, 0.05, 2.0, math.inf if deep else 5.0 + (i % 5),
                                 spec["R_sand"], wl, spec["a_water"], spec["a_ph_star"], n_bands,
                                 substrate_fraction=0.5, substrate2=spec["R_coral"], **const)

    # Check: call 0 is case `base` (deep: its rrsdp) of the stored sambuca_core output.
    want = read_columns(DATA / "sambuca_forward" / "spectra_1nm.csv", lambda r: r["case_id"] == "base")
    want = np.array(want["rrsdp" if deep else "rrs"], dtype=float)
    check = f"call 0 = case base: max |{'rrsdp' if deep else 'rrs'}/stored - 1| = {np.max(np.abs(call(0).rrs / want - 1)):.1e}"
    n = max(1, int(WORKLOADS["forward_deep" if deep else "forward_shallow"][4] * args.scale))
    for i in range(200):  # warm-up
        call(i)
    sink, t0 = 0.0, time.perf_counter()
    for i in range(n):
        sink += call(i).rrs[100]
    return n, time.perf_counter() - t0, check, stubbed


def almi_workload(args):
    import numpy as np
    stubbed = stub_io_modules(["netCDF4"])
    sys.path.insert(0, str(Path(args.dea) / "Python-aLMI-X"))
    from calc_functions import RrsAboveToBelow
    from chunkProcessLMI import chunkProcessLMI
    ini = configparser.ConfigParser()
    ini.read(DATA / "retrieval_reference" / "almi" / "almi_config.ini")
    get = lambda s, k: ast.literal_eval(ini.get(s, k))  # noqa: E731
    components, config = get("inputParameters", "components"), get("inputParameters", "chunkProcessConfig")
    g0, g1 = get("ggParameters", "g0"), get("ggParameters", "g1")
    labels = get("outputParameters", "outWavelengthLabels")
    sets: dict = {}
    band = read_columns(DATA / "retrieval_reference" / "almi" / "siop_sets_bands.csv")
    for name in dict.fromkeys(band["set_name"]):  # file order = DEA's SIOP index
        rows = [i for i, s in enumerate(band["set_name"]) if s == name]
        v = lambda c: np.array([float(band[c][i]) for i in rows])  # noqa: E731
        sets[name] = {"component": np.array(["WATER", *components]), "wavelength": v("wavelength_nm"),
                      "a_star": {"WATER": v("a_w"), "CHL": v("a_ph_star"), "CDOM": v("a_cdom_star"), "NAP": v("a_nap_star")},
                      "bb_star": {"WATER": v("bb_w"), "CHL": v("bb_ph_star"), "CDOM": v("bb_cdom_star"), "NAP": v("bb_nap_star")}}
    px = read_columns(DATA / "retrieval_reference" / "almi" / "pixels.csv", lambda r: r["dea_processed"] == "1")
    rrs = RrsAboveToBelow(np.array([[float(x) for x in px[f"Rrs_in_{lab}"]] for lab in labels]))
    res = chunkProcessLMI(sets, rrs, g0, g1, components, config)
    same = int(np.sum(res["SIOPindex"] == np.array([int(x) for x in px["dea_siop_index"]])))
    check = f"SIOP index equals the stored DEA output for {same}/{rrs.shape[1]} pixels"
    calls = max(1, int(WORKLOADS["almi"][4] * args.scale))
    t0 = time.perf_counter()
    for _ in range(calls):
        chunkProcessLMI(sets, rrs, g0, g1, components, config)
    return calls * rrs.shape[1], time.perf_counter() - t0, check, stubbed


def slsqp_workload(args, key: str):
    import collections
    import collections.abc
    import numpy as np
    collections.Callable = collections.abc.Callable  # the 2018 code imports collections.Callable
    _, stubbed = import_sambuca_core(args.sambuca_core)
    sys.path.insert(0, args.sambuca)
    import sambuca as sb
    setup = "CASI28_HI3_wide" if key == "slsqp28" else "ALOS4_MB_notebook"
    ref = DATA / "retrieval_reference" / "sambuca"
    cfg = json.loads((ref / "setups.json").read_text())[setup]
    inp = {k: np.array(v, dtype=float) for k, v in read_columns(ref / "inputs_1nm.csv").items()}
    filt = read_columns(ref / "filters_1nm.csv")
    prefix = "CASI04_b" if setup.startswith("CASI") else "ALOS_b"
    F = np.array([[float(x) for x in filt[c]] for c in filt if c.startswith(prefix)])
    assert F.shape == (len(cfg["bands"]), len(inp["wavelength_nm"])), F.shape
    wl = inp["wavelength_nm"]
    fixed = sb.create_fixed_parameter_set(
        wl, inp["a_water"], inp["a_ph_star"], [(wl, inp[s]) for s in cfg["substrates"]],
        None, None, None, None, None, **cfg["model_constants"])
    objective = sb.SciPyObjective(F, fixed, error_function=sb.distance_f,
                                  nedr=np.array([b["nedr"] for b in cfg["bands"]]))
    obs_rows = read_columns(ref / "pixel_bands.csv", lambda r: r["setup"] == setup)
    ids = sorted({int(p) for p in obs_rows["pixel_id"]})
    obs = {i: np.array([float(o) for p, o in zip(obs_rows["pixel_id"], obs_rows["obs_rrs_sub"]) if int(p) == i])
           for i in ids}
    chosen = ids[::3] if key == "slsqp28" else ids  # fixed pixel set (see the header)
    stored = read_columns(ref / "pixels.csv", lambda r: r["setup"] == setup)
    stored = {int(i): (int(k), int(n)) for i, k, n in zip(stored["pixel_id"], stored["kept_pair"], stored["nit_total"])}
    bounds = tuple(zip(cfg["p_min"], cfg["p_max"]))
    opts = dict(cfg["minimize"]["options"])
    fit = lambda i: sb.minimize(objective, np.array(cfg["p0"]), "SLSQP", bounds, opts, obs[i])  # noqa: E731
    n = max(1, int(WORKLOADS[key][4] * args.scale))
    order = [chosen[j % len(chosen)] for j in range(n)]
    fit(chosen[-1])  # warm-up
    results, t0 = [], time.perf_counter()
    for i in order:
        results.append(fit(i))
    dt = time.perf_counter() - t0
    # Check: the first pass against the package's stored results (same pair, same iterations).
    first = list(zip(order, results))[: len(chosen)]
    pair = sum(r.id == stored[i][0] for i, r in first)
    nit = sum(r.nit == stored[i][1] for i, r in first)
    check = (f"{setup}, {len(chosen)} pixels (ids {chosen[0]}, {chosen[1]}, ..., {chosen[-1]}): kept pair as stored "
             f"for {pair}/{len(first)}, SLSQP iterations (all pairs) as stored for {nit}/{len(first)}")
    return n, dt, check, stubbed


def worker(args) -> None:
    key = args.worker
    if key.startswith("forward"):
        n, dt, check, stubbed = forward_workload(args, key == "forward_deep")
    else:
        n, dt, check, stubbed = almi_workload(args) if key == "almi" else slsqp_workload(args, key)
    print(json.dumps({"n": n, "seconds": dt, "rate": n / dt, "check": check, "stubbed": stubbed}))


# ---------------------------------------------------------------- driver side

def run(cmd: list[str], core: int, pin: str) -> str:
    env = {**os.environ, **BLAS_ONE}
    pre = None
    if pin == "taskset":
        cmd = ["taskset", "-c", str(core), *cmd]
    elif pin == "affinity":
        pre = lambda: os.sched_setaffinity(0, {core})  # noqa: E731
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, preexec_fn=pre)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr[-2000:]}")
    return p.stdout


def parse_shoal(text: str) -> dict[str, float]:
    """Row label -> rate from the Markdown tables `shoal bench` prints (the rate column is the one
    headed "evaluations/s" in the water table, "pixels/s per core (noisy pixels)" in retrieval)."""
    rows, col = {}, None
    for line in text.splitlines():
        if not line.startswith("|"):
            col = None
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if col is None:  # a table's header row
            col = next((i for i, c in enumerate(cells) if c in RATE_HEADERS), -1)
        elif col >= 0 and len(cells) > col and re.fullmatch(r"\d+(\.\d+)?", cells[col]):
            rows[cells[0]] = float(cells[col])
    return rows


def loadavg() -> str:
    try:
        return Path("/proc/loadavg").read_text().strip()
    except OSError:
        return "?"


def load1() -> float:
    text = loadavg()
    return float(text.split()[0]) if text != "?" else float("nan")


def git_commit(path: str | Path) -> str:
    p = subprocess.run(["git", "-C", str(path), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    if p.returncode != 0:
        return "not a git checkout"
    dirty = subprocess.run(["git", "-C", str(path), "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()
    return p.stdout.strip() + (" (modified)" if dirty else "")


def package_version(init: Path) -> str:
    m = re.search(r"__version__\s*=\s*['\"]([^'\"]+)", init.read_text()) if init.exists() else None
    return m.group(1) if m else "?"


def machine_lines(shoal: str, paths: dict[str, str | None], load: str) -> list[str]:
    model = ""
    if shutil.which("lscpu"):
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
        model = next((ln.split(":", 1)[1].strip() for ln in out.splitlines() if ln.startswith("Model name")), "")
    try:
        import numpy
        import scipy
        libs = f"numpy {numpy.__version__}, scipy {scipy.__version__}"
    except ImportError as e:
        libs = f"numpy/scipy missing ({e})"
    shoal_v = subprocess.run([shoal, "--version"], capture_output=True, text=True).stdout.strip()
    out = [f"- Machine: {model or platform.processor() or '?'}, {os.cpu_count()} logical cores",
           f"- Load average at start: {load}",
           f"- Date: {datetime.datetime.now(datetime.timezone.utc).isoformat(timespec='seconds')}",
           f"- Python {platform.python_version()} ({sys.executable}), {libs}",
           f"- Shoal: {shoal} ({shoal_v}; repository {git_commit(REPO)})"]
    inits = {"sambuca_core": "sambuca_core/__init__.py", "sambuca": "sambuca/__init__.py", "dea": None}
    for name, path in paths.items():
        if path:
            ver = f"version {package_version(Path(path) / inits[name])}, " if inits[name] else ""
            commit = git_commit(path)
            note = "" if commit.startswith(EXPECTED[name]) else f" — the reviewer used {EXPECTED[name]}"
            out.append(f"- {name}: {path} ({ver}commit {commit}{note})")
    return out


def run_rounds(args, shoals: list[str], paths: dict, active: list[str], pin: str):
    """Every round: each section's reference workloads (one process each), then each Shoal binary's
    run of that section (the one measured first, then --shoal-before's)."""
    rates = {k: [] for k in active}
    shoal_rates = [{label: [] for key, label, _ in PAIRS if key in active} for _ in shoals]
    checks, stubbed, loads = {}, set(), []
    given = [a for name, p in paths.items() if p for a in (f"--{name.replace('_', '-')}", str(Path(p).resolve()))]
    for rnd in range(1, args.rounds + 1):
        loads.append(load1())
        for section in ("water", "retrieval"):
            keys = [k for k in active if WORKLOADS[k][1] == section]
            for key in keys:
                print(f"[round {rnd}/{args.rounds}] reference {key} ...", file=sys.stderr, flush=True)
                cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", key, "--scale", str(args.scale)]
                res = json.loads(run(cmd + given, args.core, pin).strip().splitlines()[-1])
                rates[key].append(res["rate"])
                checks.setdefault(key, res["check"])
                stubbed.update(res["stubbed"])
            for shoal, into in zip(shoals, shoal_rates) if keys else []:
                print(f"[round {rnd}/{args.rounds}] {shoal} bench --only {section} ...", file=sys.stderr, flush=True)
                cmd = [shoal, "bench", "--only", section] + (["--quick"] if args.shoal_quick else [])
                rows = parse_shoal(run(cmd, args.core, pin))
                for key, label, _ in PAIRS:
                    if key in keys:
                        into[label].append(rows.get(label))
    loads.append(load1())
    return rates, shoal_rates, checks, stubbed, loads


def report(rates: dict, shoal_rates: dict, loads: list[float], before: dict | None = None) -> None:
    """A table per (reference workload, Shoal row), then a summary and the warnings; with `before`
    (--shoal-before's rows), its ratio and new / old per round beside each."""
    warnings, summary = [], []
    if max(loads) > LOAD_LIMIT:
        warnings.append(f"1-minute load average reached {max(loads):.2f} (> {LOAD_LIMIT}): not an idle machine")
    for key, label, constant in PAIRS:
        if key not in rates:
            continue
        _, _, what, unit, _, reviewer = WORKLOADS[key]
        print(f"\n## {what} — Shoal row `{label}`\n")
        old = before.get(label, []) if before else None
        extra = " Shoal before | its ratio | new / old |" if old is not None else ""
        print(f"| round | reference, {unit} | Shoal, {unit.replace('deep ', '')} | ratio |{extra}\n"
              f"|---|---|---|---|{'---|---|---|' if extra else ''}")
        ratios, gains = [], []
        for i, (ref, sh) in enumerate(zip(rates[key], shoal_rates[label]), 1):
            ratios += [sh / ref] if sh is not None else []
            row = (f"| {i} | {fmt(ref)} | {fmt(sh) if sh is not None else 'row missing'} | "
                   f"{fmt_ratio(sh / ref) if sh is not None else '–'} |")
            if old is not None:
                o = old[i - 1] if i <= len(old) else None
                gains += [sh / o] if sh is not None and o else []
                row += (f" {fmt(o) if o else 'row missing'} | {fmt_ratio(o / ref) if o else '–'} | "
                        f"{f'{sh / o:.3f}' if sh is not None and o else '–'} |")
            print(row)
        if not ratios:
            warnings.append(f"`{label}`: no such row in Shoal's output (labels changed?)")
            continue
        ref_med, med, lo, hi = statistics.median(rates[key]), statistics.median(ratios), min(ratios), max(ratios)
        shoal_med = statistics.median([x for x in shoal_rates[label] if x is not None])
        print(f"\nMedian ratio **{fmt_ratio(med)}** (min–max {fmt_ratio(lo)}–{fmt_ratio(hi)}: "
              f"{100 * (lo / med - 1):+.1f} % / {100 * (hi / med - 1):+.1f} % of the median). Median reference "
              f"{fmt(ref_med)} {unit} (reviewer: {fmt(reviewer)}); median Shoal {fmt(shoal_med)}.")
        if gains:
            print(f"New / old: median **{statistics.median(gains):.3f}** (min–max {min(gains):.3f}–{max(gains):.3f}).")
        off = sum(abs(r / med - 1) > SPREAD_LIMIT for r in ratios)
        if off:
            warnings.append(f"`{label}`: {off} of {len(ratios)} paired ratios more than ±{SPREAD_LIMIT:.0%} "
                            "from their median")
        summary.append(f"| {what} | {label} | {fmt(ref_med)} | {fmt(reviewer)} | {fmt_ratio(med)} "
                       f"({fmt_ratio(lo)}–{fmt_ratio(hi)}) | {constant} |")
    print("\n## Summary\n\n| workload | Shoal row | reference, median | reviewer's figure | median ratio "
          "(min–max) | bench_reference.rs |\n|---|---|---|---|---|---|")
    print("\n".join(summary))
    print("\n## Warnings\n")
    print("\n".join(f"- WARNING: {w}" for w in warnings) if warnings else
          f"- none: load ≤ {LOAD_LIMIT} and every paired ratio within ±{SPREAD_LIMIT:.0%} of its median")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sambuca-core", help="checkout of sambuca_core (64483a0, version 1.2.3)")
    ap.add_argument("--sambuca", help="checkout of sambuca (stevesagar/sambuca d153684)")
    ap.add_argument("--dea", help="checkout of GeoscienceAustralia/DEA-Water-Quality (dd794b0)")
    ap.add_argument("--shoal", default=str(REPO / "target" / "release" / "shoal"))
    ap.add_argument("--shoal-before", help="an earlier build, run after --shoal in every round (new / old)")
    ap.add_argument("--rounds", type=int, default=8)
    ap.add_argument("--core", type=int, default=1, help="the one core every measurement runs on")
    ap.add_argument("--shoal-quick", action="store_true", help="pass --quick to shoal bench (same rows, noisier)")
    ap.add_argument("--scale", type=float, default=1.0,
                    help="multiply the reference workloads' fixed call counts (keep 1 for published figures)")
    ap.add_argument("--json", help="also write every per-round rate to this file")
    ap.add_argument("--worker", choices=sorted(WORKLOADS), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker(args)
        return 0

    paths = {"sambuca_core": args.sambuca_core, "sambuca": args.sambuca, "dea": args.dea}
    for name, p in paths.items():
        if p and not (Path(p) / MARKER[name]).is_file():
            ap.error(f"--{name.replace('_', '-')} {p}: not a checkout of {name} (no {MARKER[name]})")
    for flag, binary in (("--shoal", args.shoal), ("--shoal-before", args.shoal_before)):
        if binary is not None and not (os.access(binary, os.X_OK) and Path(binary).is_file()):
            ap.error(f"{flag} {binary}: not an executable (build it with `cargo build --release`)")
    shoal = str(Path(args.shoal).resolve())
    shoals = [shoal] + ([str(Path(args.shoal_before).resolve())] if args.shoal_before else [])
    pin = "taskset" if shutil.which("taskset") else "affinity" if hasattr(os, "sched_setaffinity") else "none"
    if pin != "none" and args.core not in os.sched_getaffinity(0):
        ap.error(f"--core {args.core}: not among this process's cores {sorted(os.sched_getaffinity(0))}")
    skipped, active = [], []
    for key, (needs, *_) in WORKLOADS.items():
        missing = [f"--{n.replace('_', '-')}" for n in needs if not paths[n]]
        if missing:
            skipped.append(f"- {key}: skipped, no {' / '.join(missing)} given")
        else:
            active.append(key)
    if not active:
        ap.error("no reference checkout given: nothing to measure")

    print("# Reference codes side by side with Shoal\n")
    print("\n".join(machine_lines(shoal, paths, loadavg())))
    pin_text = {"taskset": f"`taskset -c {args.core}`", "affinity": f"sched_setaffinity({{{args.core}}})",
                "none": "NOT pinned: no taskset, no sched_setaffinity"}[pin]
    quick = " --quick" if args.shoal_quick else ""
    print(f"\nMethod: {args.rounds} interleaved rounds; every measurement a fresh process on core {args.core} "
          f"({pin_text}), BLAS threads 1. Per round: the reference forward workloads, `shoal bench --only water"
          f"{quick}`, the reference retrieval workloads, `shoal bench --only retrieval{quick}`. Reference call "
          f"counts × {args.scale:g}; a section with no reference to run is not run. Ratio = Shoal's rate / the "
          "reference's rate of the same round.")
    if skipped:
        print("\n" + "\n".join(skipped))
    sys.stdout.flush()

    if args.shoal_before:
        print(f"- Shoal before: {shoals[1]} (run after the Shoal above in every round)")
    rates, all_shoal, checks, stubbed, loads = run_rounds(args, shoals, paths, active, pin)
    shoal_rates, before = all_shoal[0], all_shoal[1] if len(all_shoal) > 1 else None
    print(f"\n- Load average at end: {loadavg()}; 1-minute load before each round and at the end: "
          f"{', '.join(f'{x:.2f}' for x in loads)}")
    if stubbed:
        print(f"- Not installed, replaced by empty modules (file I/O only, never on a timed path): "
              f"{', '.join(sorted(stubbed))}")
    print("\n## Checks (first round: the workload is the reference configuration)\n")
    print("\n".join(f"- {key}: {text}" for key, text in checks.items()))
    report(rates, shoal_rates, loads, before)
    if args.json:
        Path(args.json).write_text(json.dumps({"reference": rates, "shoal": shoal_rates, "shoal_before": before,
                                               "loads": loads,
                                               "checks": checks, "args": vars(args)}, indent=1))
    return 0


def fmt(v: float) -> str:
    return f"{v:,.0f}" if v >= 100 else f"{v:.3g}"


def fmt_ratio(r: float) -> str:
    return f"{r:,.0f}×" if r >= 100 else f"{r:.1f}×" if r >= 10 else f"{r:.2f}×"


if __name__ == "__main__":
    sys.exit(main())
