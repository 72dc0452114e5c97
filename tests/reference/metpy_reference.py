#!/usr/bin/env python3
"""Reference values for tests/physics_reference.rs, computed with MetPy.

Generated once with MetPy 1.7.1 (numpy 2.4.6, Python 3.11) and committed as
tests/reference/lcl.csv and tests/reference/parcel_profile.csv; re-run with
`pip install metpy==1.7.1 && python3 tests/reference/metpy_reference.py`.

For each sounding: the lifting condensation level of the lowest level's air
(`metpy.calc.lcl`), its height (log-pressure interpolation between the
sounding's levels) and the temperature of that air lifted without mixing
(`metpy.calc.parcel_profile`: dry adiabat, then the pseudo-adiabat
`moist_lapse`). A sounding with empty pressures is completed level by level
with the hypsometric equation, using MetPy's `mixing_ratio` and
`virtual_temperature` (an implementation independent of cumulus').
"""
import csv
import math
import os

import metpy
import metpy.calc as mpcalc
import numpy as np
from metpy.constants import Rd, g
from metpy.units import units

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
SOUNDINGS = {
    "bomex": os.path.join(ROOT, "scenes", "bomex_sounding.csv"),
    "continental_summer": os.path.join(ROOT, "tests", "data", "continental_summer.csv"),
    "tropical_humid": os.path.join(ROOT, "tests", "data", "tropical_humid.csv"),
    "cool_maritime": os.path.join(ROOT, "tests", "data", "cool_maritime.csv"),
}


def read(path):
    z, p, t, td = [], [], [], []
    with open(path) as f:
        for row in csv.DictReader(line for line in f if not line.startswith("#")):
            z.append(float(row["height_m"]))
            p.append(float(row["pressure_hPa"]) if row["pressure_hPa"].strip() else math.nan)
            t.append(float(row["temperature_C"]))
            td.append(float(row["dewpoint_C"]))
    z, p, t, td = map(np.array, (z, p, t, td))
    for i in range(1, len(p)):
        if math.isnan(p[i]):
            tv = []
            for k in (i - 1, i):
                w = mpcalc.mixing_ratio(mpcalc.saturation_vapor_pressure(td[k] * units.degC), p[i - 1] * units.hPa)
                tv.append(mpcalc.virtual_temperature(t[k] * units.degC, w).to("K").m)
            tv_mean = (tv[1] - tv[0]) / math.log(tv[1] / tv[0]) if tv[1] != tv[0] else tv[0]
            p[i] = p[i - 1] * math.exp(-g.m * (z[i] - z[i - 1]) / (Rd.m * tv_mean))
    return z, p, t, td


def height_at(z, p, p_target):
    lnp = np.log(p)
    for i in range(1, len(p)):
        if p[i] <= p_target:
            f = (math.log(p_target) - lnp[i - 1]) / (lnp[i] - lnp[i - 1])
            return z[i - 1] + f * (z[i] - z[i - 1])
    return math.nan


def main():
    lcl_rows, prof_rows = [], []
    for name, path in SOUNDINGS.items():
        z, p, t, td = read(path)
        p_lcl, t_lcl = mpcalc.lcl(p[0] * units.hPa, t[0] * units.degC, td[0] * units.degC)
        p_lcl, t_lcl = p_lcl.to("hPa").m, t_lcl.to("K").m
        z_lcl = height_at(z, p, p_lcl)
        lcl_rows.append((name, p_lcl, t_lcl, z_lcl))
        prof = mpcalc.parcel_profile(p * units.hPa, t[0] * units.degC, td[0] * units.degC).to("K").m
        for zi, pi, ti in zip(z, p, prof):
            prof_rows.append((name, zi, pi, ti))
    with open(os.path.join(HERE, "lcl.csv"), "w") as f:
        f.write(f"# MetPy {metpy.__version__}: metpy.calc.lcl of each sounding's lowest level\n")
        f.write("sounding,lcl_pressure_hPa,lcl_temperature_K,lcl_height_m\n")
        for r in lcl_rows:
            f.write("%s,%.6f,%.6f,%.3f\n" % r)
    with open(os.path.join(HERE, "parcel_profile.csv"), "w") as f:
        f.write(f"# MetPy {metpy.__version__}: metpy.calc.parcel_profile of each sounding's lowest level\n")
        f.write("sounding,height_m,pressure_hPa,parcel_T_K\n")
        for r in prof_rows:
            f.write("%s,%.3f,%.6f,%.6f\n" % r)


if __name__ == "__main__":
    main()
