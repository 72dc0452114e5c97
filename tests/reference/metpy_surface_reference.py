#!/usr/bin/env python3
"""LCL and pseudo-adiabat references for eleven surface air states from
-20 °C to 48 °C, for tests/physics_reference.rs, computed with MetPy 1.7.1.

Re-run with `pip install metpy==1.7.1 numpy &&
python3 tests/reference/metpy_surface_reference.py`. It writes

- tests/data/surface/NAME.csv: a sounding (this project's CSV format)
  starting at each surface state: levels every 100 m, temperature falling
  6.5 K/km, dewpoint falling 2 K/km (kept at least 1 K below the
  temperature), pressures filled with the hypsometric equation using
  MetPy's `mixing_ratio` and `virtual_temperature` and written out, so that
  cumulus and this script read the very same pressures. The column ends one
  level above 3 km over the LCL.
- tests/reference/surface_lcl.csv: `metpy.calc.lcl` of the surface air
  (pressure, temperature) and its height in the column by log-pressure
  interpolation between levels (as metpy_reference.py's `height_at` and
  cumulus' `lift_sounding`).
- tests/reference/surface_profile.csv: `metpy.calc.parcel_profile` of the
  surface air (dry adiabat, then the pseudo-adiabat `moist_lapse`) at every
  level up to 3 km above the LCL.

The states (name: temperature °C, dewpoint °C, pressure hPa):

- arctic_minus20: -20, -24, 1030 (the coldest; cold, below 0 °C)
- winter_minus5: -5, -9, 1000 (cold, below 0 °C)
- near_freezing: 2, 0, 1015
- maritime_15: 15, 12, 1013 (ordinary)
- spring_20: 20, 8, 1005 (ordinary)
- high_plains_25: 25, 5, 850 (elevated ground)
- subtropical_30: 30, 22, 1008 (ordinary, humid)
- tropical_ocean_29: 29, 25, 1010
- monsoon_35: 35, 27, 995
- desert_40: 40, -5, 960 (very dry: LCL some 5.5 km up)
- hot_humid_48: 48, 25, 1000 (the hot, humid extreme)
"""
import math
import os

import metpy
import metpy.calc as mpcalc
import numpy as np
from metpy.constants import Rd, g
from metpy.units import units

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
DATA = os.path.join(ROOT, "tests", "data", "surface")

# name: (temperature °C, dewpoint °C, pressure hPa)
STATES = {
    "arctic_minus20": (-20.0, -24.0, 1030.0),
    "winter_minus5": (-5.0, -9.0, 1000.0),
    "near_freezing": (2.0, 0.0, 1015.0),
    "maritime_15": (15.0, 12.0, 1013.0),
    "spring_20": (20.0, 8.0, 1005.0),
    "high_plains_25": (25.0, 5.0, 850.0),
    "subtropical_30": (30.0, 22.0, 1008.0),
    "tropical_ocean_29": (29.0, 25.0, 1010.0),
    "monsoon_35": (35.0, 27.0, 995.0),
    "desert_40": (40.0, -5.0, 960.0),
    "hot_humid_48": (48.0, 25.0, 1000.0),
}

DZ_M = 100.0
LAPSE_K_PER_M = 6.5e-3
DEWPOINT_LAPSE_K_PER_M = 2.0e-3
TOP_M = 12_000.0
ABOVE_LCL_M = 3000.0


def virtual_temperature_k(t_c, td_c, p_hpa):
    w = mpcalc.mixing_ratio(mpcalc.saturation_vapor_pressure(td_c * units.degC), p_hpa * units.hPa)
    return mpcalc.virtual_temperature(t_c * units.degC, w).to("K").m


def column(t0, td0, p0):
    """Heights, pressures (rounded as written), temperatures, dewpoints."""
    n = int(TOP_M / DZ_M) + 1
    z = np.arange(n) * DZ_M
    t = np.round(t0 - LAPSE_K_PER_M * z, 3)
    td = np.round(np.minimum(td0 - DEWPOINT_LAPSE_K_PER_M * z, t - 1.0), 3)
    t[0], td[0] = t0, td0
    p = np.empty(n)
    p[0] = p0
    for i in range(1, n):
        # Both levels' virtual temperatures at the pressure below (as
        # metpy_reference.py), their log-mean over the layer.
        tv = [virtual_temperature_k(t[k], td[k], p[i - 1]) for k in (i - 1, i)]
        tv_mean = (tv[1] - tv[0]) / math.log(tv[1] / tv[0]) if tv[1] != tv[0] else tv[0]
        p[i] = round(p[i - 1] * math.exp(-g.m * DZ_M / (Rd.m * tv_mean)), 4)
    return z, p, t, td


def height_at(z, p, p_target):
    lnp = np.log(p)
    for i in range(1, len(p)):
        if p[i] <= p_target:
            f = (math.log(p_target) - lnp[i - 1]) / (lnp[i] - lnp[i - 1])
            return z[i - 1] + f * (z[i] - z[i - 1])
    return math.nan


def main():
    os.makedirs(DATA, exist_ok=True)
    lcl_rows, prof_rows = [], []
    for name, (t0, td0, p0) in STATES.items():
        z, p, t, td = column(t0, td0, p0)
        p_lcl, t_lcl = mpcalc.lcl(p0 * units.hPa, t0 * units.degC, td0 * units.degC)
        p_lcl, t_lcl = p_lcl.to("hPa").m, t_lcl.to("K").m
        z_lcl = height_at(z, p, p_lcl)
        assert not math.isnan(z_lcl), name
        # One level above LCL + 3 km.
        top = int(np.searchsorted(z, z_lcl + ABOVE_LCL_M)) + 1
        z, p, t, td = z[:top], p[:top], t[:top], td[:top]
        with open(os.path.join(DATA, f"{name}.csv"), "w") as f:
            f.write(
                f"# made by tests/reference/metpy_surface_reference.py: {t0} °C, "
                f"dewpoint {td0} °C, {p0} hPa at the ground\n"
            )
            f.write("height_m,pressure_hPa,temperature_C,dewpoint_C\n")
            for zi, pi, ti, tdi in zip(z, p, t, td):
                f.write(f"{zi:.0f},{pi:.4f},{ti:.3f},{tdi:.3f}\n")
        lcl_rows.append((name, t0, td0, p0, p_lcl, t_lcl, z_lcl))
        prof = mpcalc.parcel_profile(p * units.hPa, t0 * units.degC, td0 * units.degC).to("K").m
        for zi, pi, ti in zip(z, p, prof):
            if zi <= z_lcl + ABOVE_LCL_M:
                prof_rows.append((name, zi, pi, ti))
    script = "tests/reference/metpy_surface_reference.py"
    with open(os.path.join(HERE, "surface_lcl.csv"), "w") as f:
        f.write(
            f"# made by {script} (MetPy {metpy.__version__}): metpy.calc.lcl of each "
            "surface state; height in tests/data/surface/NAME.csv\n"
        )
        f.write(
            "state,temperature_C,dewpoint_C,pressure_hPa,"
            "lcl_pressure_hPa,lcl_temperature_K,lcl_height_m\n"
        )
        for r in lcl_rows:
            f.write("%s,%.2f,%.2f,%.2f,%.6f,%.6f,%.3f\n" % r)
    with open(os.path.join(HERE, "surface_profile.csv"), "w") as f:
        f.write(
            f"# made by {script} (MetPy {metpy.__version__}): metpy.calc.parcel_profile "
            "of each surface state at the levels of tests/data/surface/NAME.csv up to "
            "3 km above its LCL\n"
        )
        f.write("state,height_m,pressure_hPa,parcel_T_K\n")
        for r in prof_rows:
            f.write("%s,%.0f,%.4f,%.6f\n" % r)


if __name__ == "__main__":
    main()
