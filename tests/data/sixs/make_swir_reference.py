"""6SV 1.1 reference values at SWIR wavelengths for Shoal's tests (tests/data/sixs/).

For each case (geometry, water vapour, aerosol, target altitude) and each wavelength (monochromatic)
or Sentinel-2A MSI band (6SV's filter integration over the ESA SRF v3 that Py6S carries), records:
two-way (sun-surface-sensor) total gaseous transmittance and water-vapour transmittance, Rayleigh
and aerosol optical depths, and the intrinsic atmospheric reflectance over a black Lambertian
surface ("reflectance I", Rayleigh, aerosol, total; no gas absorption).
Usage: python sixs_swir_reference.py SIXS_BINARY OUT.csv
"""
import re, sys
import Py6S

BINARY, OUT = sys.argv[1], sys.argv[2]
CASES = {
    # name: (sun zenith, view zenith, relative azimuth, W cm, O3 atm-cm, aerosol, AOT550, target km)
    "A": (40.0, 10.0, 90.0, 2.0, 0.3, "maritime", 0.1, 0.0),
    "B": (60.0, 30.0, 90.0, 4.0, 0.3, "continental", 0.2, 0.0),
    "C": (30.0, 0.0, 90.0, 0.5, 0.3, "maritime", 0.05, 1.0),
}
WAVELENGTHS_NM = [865, 1020, 1050, 1240, 1375, 1610, 1650, 2130, 2200, 2250]
BANDS = {"S2A_B8A": Py6S.PredefinedWavelengths.S2A_MSI_8A, "S2A_B11": Py6S.PredefinedWavelengths.S2A_MSI_11, "S2A_B12": Py6S.PredefinedWavelengths.S2A_MSI_12}
AEROSOLS = {"maritime": Py6S.AeroProfile.Maritime, "continental": Py6S.AeroProfile.Continental}


def triple(text, label):
    """The three numbers of the summary line `label : a b c`."""
    for line in text.splitlines():
        if label in line:
            nums = re.findall(r"[-+]?\d+\.\d+(?:[eE][-+]?\d+)?", line.split(":", 1)[1])
            return [float(x) for x in nums[:3]]
    raise KeyError(label)


def run(case, wavelength):
    sz, vz, raz, w, o3, aer, aot, alt = CASES[case]
    s = Py6S.SixS(BINARY)
    s.atmos_profile = Py6S.AtmosProfile.UserWaterAndOzone(w, o3)
    s.aero_profile = Py6S.AeroProfile.PredefinedType(AEROSOLS[aer])
    s.aot550 = aot
    s.geometry = Py6S.Geometry.User()
    s.geometry.solar_z, s.geometry.solar_a, s.geometry.view_z, s.geometry.view_a = sz, 0.0, vz, raz
    s.geometry.month, s.geometry.day = 6, 21
    s.altitudes.set_sensor_satellite_level()
    if alt > 0:
        s.altitudes.set_target_custom_altitude(alt)
    else:
        s.altitudes.set_target_sea_level()
    s.ground_reflectance = Py6S.GroundReflectance.HomogeneousLambertian(0.0)
    s.wavelength = Py6S.Wavelength(wavelength / 1000.0) if isinstance(wavelength, (int, float)) else Py6S.Wavelength(wavelength)
    s.run()
    t = s.outputs.fulltext
    gas = triple(t, "global gas. trans. :")
    water = triple(t, 'water   "     "    :')
    depth = triple(t, "optical depth total:")
    refl = triple(t, "reflectance I      :")
    pressure = s.outputs.values["ground_pressure"]
    return [gas[2], water[2], depth[0], depth[1], refl[0], refl[1], refl[2], pressure]


with open(OUT, "w") as f:
    f.write("case,sun_zenith_deg,view_zenith_deg,relative_azimuth_deg,water_vapour_cm,ozone_atm_cm,aerosol,aot550,target_km,band,"
            "t_gas_two_way,t_h2o_two_way,tau_rayleigh,tau_aerosol,rho_rayleigh,rho_aerosol,rho_path,pressure_hpa\n")
    for case, p in CASES.items():
        for wl in WAVELENGTHS_NM:
            r = run(case, wl)
            f.write(",".join(str(x) for x in [case, *p, f"{wl}nm", *r]) + "\n")
        for name, band in BANDS.items():
            r = run(case, band)
            f.write(",".join(str(x) for x in [case, *p, name, *r]) + "\n")
