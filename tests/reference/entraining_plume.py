"""An independent entraining-plume reference for the deep-convection scene
(scenes/deep_convection.toml): how high does one parcel of the scene rise,
undiluted and at the scene's entrainment rates?

Written separately from the simulator, with MetPy 1.7.1's constants and its
saturation vapour pressure (Ambaum 2020, checked against MetPy below), and a
different formulation of the same physics:

- the parcel's thermodynamic state is its reversible moist entropy per unit
  mass of dry air (Emanuel 1994, Eq. 4.5.9, with the relative-humidity term
  when unsaturated) and its total water r_t; lifting conserves both (the
  simulator carries Emanuel's exact theta_l instead);
- entrainment mixes a fraction 1 - exp(-eps |w| dt) of environment air in at
  constant pressure, conserving moist enthalpy (c_pd + r_t c_l) T + L_v r_v
  and r_t, and the entropy of the mixture is recomputed from its temperature
  (the simulator relaxes theta_l linearly);
- detrainment removes condensate at the parcel's temperature at the scene's
  rate, faster while negatively buoyant;
- buoyancy is from the exact density temperature
  T (1 + r_v / epsilon) / (1 + r_t) (the simulator's theta_v uses the
  linearised virtual coefficient);
- the vertical velocity obeys dw/dt = B / (1 + virtual mass) - k w |w| with
  k = eps + 3/8 C_D / R, integrated with midpoint steps of 0.1 s (the
  simulator: velocity Verlet with implicit drag at the scene's 5 s).

The environment is the scene's sounding interpolated as the simulator does
(T and mixing ratio linear in height, ln p linear in height). The parcel
starts at rest at the release height with the environment's water and the
scene's theta excess. For each case the script writes the apex (the highest
point of the first rise) and the level of neutral buoyancy (where the rising
parcel's buoyancy first turns negative above its LCL):
tests/reference/entraining_plume_deep.csv.

    pip install metpy==1.7.1
    python3 tests/reference/entraining_plume.py
    python3 tests/reference/entraining_plume.py --mix theta_l

`--mix theta_l` mixes Emanuel's exact theta_l linearly, as the simulator
does, and only prints the apexes (nothing is written): it shows how much of
the simulator's difference from this reference is the mixing variable.
"""

import math
import os
import sys
import tomllib

import numpy as np
import metpy.calc as mpcalc
from metpy.constants import Cp_d, Cp_l, Cp_v, Lv, Rd, Rv, epsilon, g
from metpy.units import units
from scipy.optimize import brentq

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

cpd, cl, cpv, lv0, rd, rv, eps, grav = (
    Cp_d.m, Cp_l.m, Cp_v.m, Lv.m, Rd.m, Rv.m, epsilon.m, g.m)
T0, E0 = 273.16, 611.2


def lv(t):
    return lv0 - (cl - cpv) * (t - T0)


def es(t):
    # Ambaum (2020) Eq. 13, MetPy's form.
    return E0 * (T0 / t) ** ((cl - cpv) / rv) * math.exp((lv0 / T0 - lv(t) / t) / rv)


for tc in (-40.0, 0.0, 30.0):
    want = mpcalc.saturation_vapor_pressure(tc * units.degC).to("Pa").m
    assert abs(es(tc + 273.15) / want - 1.0) < 1e-9, (tc, es(tc + 273.15), want)


def rs(t, p):
    e = min(es(t), 0.5 * p)
    return eps * e / (p - e)


def split(t, p, rt):
    """Vapour and condensate of r_t at t, p."""
    rvap = min(rt, rs(t, p))
    return rvap, rt - rvap


def entropy(t, p, rt):
    rvap, _ = split(t, p, rt)
    e = p * rvap / (eps + rvap)
    h = e / es(t)
    s = (cpd + rt * cl) * math.log(t) - rd * math.log(p - e) + lv(t) * rvap / t
    if rvap > 0.0 and h < 1.0:
        s -= rvap * rv * math.log(h)
    return s


def enthalpy(t, p, rt):
    rvap, _ = split(t, p, rt)
    return (cpd + rt * cl) * t + lv(t) * rvap


def theta_l(t, p, rt):
    """Emanuel's (1994) Eq. 4.5.15, for the --mix theta_l variant."""
    rvap, rl = split(t, p, rt)
    c = cpd + rt * cpv
    chi, gam = (rd + rt * rv) / c, rt * rv / c
    y = math.log(t) + chi * math.log(1e5 / p * (eps + rvap) / (eps + rt))
    if rl > 0.0:
        y -= gam * math.log(rvap / rt) + lv(t) * rl / (c * t)
    return math.exp(y)


MIXED = theta_l if "--mix" in sys.argv and "theta_l" in sys.argv else enthalpy


def temperature_from(fn, target, p, rt):
    return brentq(lambda t: fn(t, p, rt) - target, 150.0, 360.0, xtol=1e-9)


def density_temperature(t, p, rt):
    rvap, _ = split(t, p, rt)
    return t * (1.0 + rvap / eps) / (1.0 + rt)


def load_sounding(path):
    d = np.genfromtxt(path, delimiter=",", names=True)
    z = d["height_m"]
    p = d["pressure_hPa"] * 100.0
    t = d["temperature_C"] + 273.15
    r = mpcalc.mixing_ratio(mpcalc.saturation_vapor_pressure(d["dewpoint_C"] * units.degC),
                            p * units.Pa).m
    return z, p, t, r


class Environment:
    def __init__(self, path):
        self.z, p, self.t, self.r = load_sounding(path)
        self.lnp = np.log(p)

    def at(self, z):
        p = math.exp(np.interp(z, self.z, self.lnp))
        t = float(np.interp(z, self.z, self.t))
        r = float(np.interp(z, self.z, self.r))
        return p, t, r


def rise(env, phys, radius, entrain_coefficient, dt=0.1):
    z = phys["release_height_m"]
    p, te, re = env.at(z)
    rt = re
    chi = (rd + rt * rv) / (cpd + rt * cpv)
    t0 = te + phys["initial_excess_k"] * (p / 1e5) ** chi
    s = entropy(t0, p, rt)
    w = 0.0
    eps_m = entrain_coefficient / radius
    k = eps_m + 0.375 * phys["drag_coefficient"] / radius
    vm = 1.0 + phys["virtual_mass"]
    det_rate, sorting = phys["detrainment_rate_per_s"], phys["sorting_factor"]
    start = (t0, rt, z)

    def buoyancy(z, s, rt):
        p, te, re = env.at(z)
        t = temperature_from(entropy, s, p, rt)
        tr = density_temperature(t, p, rt)
        return grav * (tr - density_temperature(te, p, re)) / density_temperature(te, p, re), t, p

    top, lnb, cloudy = z, None, False
    b, t, p = buoyancy(z, s, rt)
    for _ in range(int(7200 / dt)):
        # Midpoint step of the momentum equation, thermodynamics frozen.
        wm = w + 0.5 * dt * (b / vm - k * w * abs(w))
        zm = z + 0.5 * dt * w
        bm, _, _ = buoyancy(zm, s, rt)
        w_new = w + dt * (bm / vm - k * wm * abs(wm))
        z += dt * wm
        w = w_new
        p, te, re = env.at(z)
        t = temperature_from(entropy, s, p, rt)
        # Entrainment: isobaric mixing of environment air, enthalpy kept.
        if eps_m > 0.0:
            f = 1.0 - math.exp(-eps_m * abs(wm) * dt)
            hmix = (1.0 - f) * MIXED(t, p, rt) + f * MIXED(te, p, re)
            rt = (1.0 - f) * rt + f * re
            t = temperature_from(MIXED, hmix, p, rt)
        b_now = grav * (density_temperature(t, p, rt) - density_temperature(te, p, re)) \
            / density_temperature(te, p, re)
        # Detrainment: condensate leaves at the parcel's temperature.
        _, rl = split(t, p, rt)
        if rl > 0.0:
            cloudy = True
            rate = det_rate * (1.0 + sorting if b_now < 0.0 else 1.0)
            rt -= rl * (1.0 - math.exp(-rate * dt))
        s = entropy(t, p, rt)
        b, t, p = buoyancy(z, s, rt)
        if cloudy and lnb is None and b < 0.0 and w > 0.0 and z > 2000.0:
            lnb = z
        top = max(top, z)
        if w < 0.0 and z > 1000.0:
            break
    return start, top, lnb


def main():
    scene_path = os.path.join(ROOT, "scenes/deep_convection.toml")
    with open(scene_path, "rb") as f:
        scene = tomllib.load(f)
    ph = scene["physics"]
    phys = {
        "release_height_m": ph["release_height_m"],
        "initial_excess_k": ph["initial_excess_k"],
        "virtual_mass": ph.get("virtual_mass", 0.5),
        "drag_coefficient": ph.get("drag_coefficient", 0.5),
        "detrainment_rate_per_s": ph.get("detrainment", {}).get("rate_per_s", 1.0 / 900.0),
        "sorting_factor": ph.get("detrainment", {}).get("sorting_factor", 3.0),
    }
    assert ph.get("initial_excess_qt_gkg", 1.0) == 0.0, "the reference starts with env water"
    coefficient = ph["entrainment"]["coefficient"]
    radius, jitter = ph["radius_m"], ph["radius_jitter"]
    env = Environment(os.path.join(ROOT, "scenes", scene["atmosphere"]["sounding"]))
    cases = [("undiluted", radius, 0.0)]
    for r in (radius * (1.0 + jitter), radius, radius * (1.0 - jitter)):
        cases.append((f"radius_{r:.0f}m", r, coefficient))
    rows = []
    for name, r, c in cases:
        start, top, lnb = rise(env, phys, r, c)
        rows.append((name, r, c, c / r, top, lnb))
        print(f"{name}: R {r:.0f} m, eps {c / r:.2e} /m: apex {top:.0f} m, LNB {lnb}")
    if MIXED is not enthalpy:
        return
    with open(os.path.join(HERE, "entraining_plume_deep.csv"), "w") as f:
        f.write("# made by tests/reference/entraining_plume.py (MetPy 1.7.1 constants)\n")
        f.write(f"# start_T_K={start[0]:.5f} start_rt_kgkg={start[1]:.8f} start_z_m={start[2]:.1f}\n")
        f.write("case,radius_m,entrainment_coefficient,entrainment_per_m,apex_m,lnb_m\n")
        for name, r, c, e, top, lnb in rows:
            f.write(f"{name},{r:.1f},{c:.4f},{e:.6e},{top:.1f},{lnb if lnb else float('nan'):.1f}\n")


if __name__ == "__main__":
    main()
