#!/usr/bin/env python3
"""Writes scenes/bomex_sounding.csv from the BOMEX case definition.

BOMEX (Siebesma et al. 2003, J. Atmos. Sci. 60, 1201-1219), surface pressure
1015 hPa: liquid-water potential temperature 298.7 K from 0 to 520 m, 302.4 K
at 1480 m, 308.2 K at 2000 m, 311.85 K at 3000 m; total water 17.0, 16.3,
10.7, 4.2, 3.0 g/kg at 0, 520, 1480, 2000, 3000 m, linear in between. The
initial profile is unsaturated, so theta = theta_l and q_v = q_t.

Pressure is integrated hydrostatically (dp/dz = -p g / (R_d T_v)) on a 1 m
grid with the same constants as src/sim/constants.rs; the dewpoint inverts
Ambaum's (2020) saturation vapour pressure, as src/sim/thermo.rs does, so
the mixing ratio read back is the case's q_t. Pure Python, no packages:
run `python3 tests/reference/make_bomex_sounding.py`.
"""
import math
import os

G, RD, CP = 9.80665, 287.04, 1004.7
EPS = RD / 461.5
KAPPA = RD / CP
P_SURFACE = 101500.0

THETA_L = [(0, 298.7), (520, 298.7), (1480, 302.4), (2000, 308.2), (3000, 311.85)]
QT_GKG = [(0, 17.0), (520, 16.3), (1480, 10.7), (2000, 4.2), (3000, 3.0)]


def interp(table, z):
    for (z0, v0), (z1, v1) in zip(table, table[1:]):
        if z0 <= z <= z1:
            return v0 + (v1 - v0) * (z - z0) / (z1 - z0)
    raise ValueError(z)


CP_L, CP_V, RV_A, L0, T0 = 4219.4, 1860.078011865639, 461.52311572606084, 2.50084e6, 273.16


def es_ambaum(t):
    lat = L0 - (CP_L - CP_V) * (t - T0)
    return 611.2 * (T0 / t) ** ((CP_L - CP_V) / RV_A) * math.exp((L0 / T0 - lat / t) / RV_A)


def dewpoint_c(q, p):
    e = q * p / (EPS + q)
    ln = math.log(e / 611.2)
    t = 273.15 + 243.5 * ln / (17.67 - ln)
    for _ in range(20):
        lat = L0 - (CP_L - CP_V) * (t - T0)
        t -= (math.log(es_ambaum(t)) - math.log(e)) / (lat / (RV_A * t * t))
    return t - 273.15


def main():
    out = os.path.join(os.path.dirname(__file__), "..", "..", "scenes", "bomex_sounding.csv")
    rows = []
    ln_p = math.log(P_SURFACE)

    def tv(z, p):
        t = interp(THETA_L, z) * (p / 1e5) ** KAPPA
        return t * (1 + 0.608 * interp(QT_GKG, z) * 1e-3), t

    for z in range(0, 3001):
        p = math.exp(ln_p)
        tv0, t = tv(z, p)
        if z % 20 == 0:
            q = interp(QT_GKG, z) * 1e-3
            rows.append((z, p / 100, t - 273.15, dewpoint_c(q, p)))
        if z < 3000:
            guess = math.exp(ln_p - G / (RD * tv0))
            tv1, _ = tv(z + 1, guess)
            ln_p -= G * 0.5 * (1 / tv0 + 1 / tv1) / RD
    with open(out, "w") as f:
        f.write("# BOMEX initial profile (Siebesma et al. 2003), made by tests/reference/make_bomex_sounding.py\n")
        f.write("height_m,pressure_hPa,temperature_C,dewpoint_C\n")
        for z, p, t, td in rows:
            f.write(f"{z},{p:.3f},{t:.4f},{td:.4f}\n")


if __name__ == "__main__":
    main()
