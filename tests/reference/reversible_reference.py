"""An independent exact reversible moist adiabat for `cumulus profile
--adiabat reversible`, with MetPy 1.7.1's constants and saturation vapour
pressure (Ambaum 2020).

The parcel (the lowest level's air) rises unsaturated to its LCL (MetPy's
`lcl`), then conserves its total water and its reversible moist entropy per
unit mass of dry air (Emanuel 1994, Eq. 4.5.9, saturated so H = 1):

    s = (c_pd + r_t c_l) ln T - R_d ln(p - e_s) + L_v(T) r_s / T,
    L_v(T) = L_v0 - (c_l - c_pv)(T - T0),

solved for T at every level with brentq. Writes the sounding it used
(tests/data/deep_tropical.csv: a deep, moist tropical column to 16 km, 161
levels, pressures from the hypsometric equation) and the parcel
temperatures (tests/reference/reversible_deep_tropical.csv).

    pip install metpy==1.7.1
    python3 tests/reference/reversible_reference.py
"""

import math
import os

import numpy as np
import metpy.calc as mpcalc
from metpy.constants import Cp_d, Cp_l, Cp_v, Lv, Rd, Rv, epsilon, g
from metpy.units import units
from scipy.optimize import brentq

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

cpd, cl, cpv, lv0, rd, rv, eps = (Cp_d.m, Cp_l.m, Cp_v.m, Lv.m, Rd.m, Rv.m, epsilon.m)
T0 = 273.16


def es(t):
    return mpcalc.saturation_vapor_pressure(t * units.K).to("Pa").m


def entropy(t, p, rt):
    e = es(t)
    rs = eps * e / (p - e)
    lv = lv0 - (cl - cpv) * (t - T0)
    return (cpd + rt * cl) * math.log(t) - rd * math.log(p - e) + lv * rs / t


def sounding(n=161):
    z = np.linspace(0.0, 16000.0, n)
    t = 27.0 - 6.5e-3 * np.minimum(z, 11000.0)
    td = t - 2.0 - 1.5e-3 * z
    p = np.empty(n)
    p[0] = 101000.0
    for i in range(1, n):
        tv = []
        for k in (i - 1, i):
            r = mpcalc.mixing_ratio(mpcalc.saturation_vapor_pressure(td[k] * units.degC),
                                    (p[k - 1] if k == i else p[k]) * units.Pa).m
            tv.append((t[k] + 273.15) * (1.0 + r / eps) / (1.0 + r))
        p[i] = p[i - 1] * math.exp(-g.m * (z[i] - z[i - 1]) / (rd * 0.5 * (tv[0] + tv[1])))
    return z, p, t, td


z, p, t, td = sounding()
with open(os.path.join(ROOT, "tests/data/deep_tropical.csv"), "w") as f:
    f.write("height_m,pressure_hPa,temperature_C,dewpoint_C\n")
    for row in zip(z, p, t, td):
        f.write(f"{row[0]:.1f},{row[1] / 100:.4f},{row[2]:.4f},{row[3]:.4f}\n")

p_lcl, t_lcl = mpcalc.lcl(p[0] * units.Pa, t[0] * units.degC, td[0] * units.degC)
p_lcl, t_lcl = p_lcl.to("Pa").m, t_lcl.to("K").m
rt = mpcalc.mixing_ratio(mpcalc.saturation_vapor_pressure(td[0] * units.degC),
                         p[0] * units.Pa).m
s0 = entropy(t_lcl, p_lcl, rt)
with open(os.path.join(HERE, "reversible_deep_tropical.csv"), "w") as f:
    f.write("# made by tests/reference/reversible_reference.py (MetPy 1.7.1 constants)\n")
    f.write(f"# lcl_pressure_Pa={p_lcl:.3f} lcl_temperature_K={t_lcl:.5f} rt_kgkg={rt:.7f}\n")
    f.write("height_m,pressure_Pa,parcel_T_K,parcel_qc_gkg\n")
    for zi, pi in zip(z, p):
        if pi >= p_lcl:
            continue
        ti = brentq(lambda x: entropy(x, pi, rt) - s0, 150.0, t_lcl + 1.0, xtol=1e-10)
        e = es(ti)
        qc = rt - eps * e / (pi - e)
        f.write(f"{zi:.1f},{pi:.3f},{ti:.5f},{qc * 1e3:.5f}\n")
print("wrote tests/data/deep_tropical.csv and tests/reference/reversible_deep_tropical.csv")
