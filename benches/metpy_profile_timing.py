"""Times MetPy 1.7's `lcl` + `parcel_profile` in-process on the analytic
tropical soundings that `benches/physics.rs` (group
`lcl_and_pseudo_profile`) times cumulus on: 17, 401 and 4,001 levels from 0
to 16 km, T = 27 C - 6.5 K/km to 11 km then isothermal, dewpoint depression
2 K + 1.5 K/km, 1010 hPa at the ground, pressures from the hypsometric
equation with MetPy's constants.

It also measures MetPy's integration error against an exact reference: the
pseudo-adiabat ODE MetPy integrates (`moist_lapse`), solved with scipy's
solve_ivp at rtol 1e-12 from MetPy's own LCL; cumulus' own error against
5 Pa RK4 steps is checked by `pseudo_adiabat_steps_converge` (src/sim/lift.rs).

    pip install metpy==1.7.1
    python3 benches/metpy_profile_timing.py
"""

import time

import numpy as np
import metpy.calc as mpcalc
from metpy.constants import Rd, g, epsilon, Cp_d, Lv
from metpy.units import units
from scipy.integrate import solve_ivp


def sounding(n):
    z = np.linspace(0.0, 16000.0, n)
    t = 27.0 - 6.5e-3 * np.minimum(z, 11000.0)
    td = t - 2.0 - 1.5e-3 * z
    p = np.empty(n)
    p[0] = 1010.0
    rd, gg = Rd.m, g.m
    for i in range(1, n):
        # Virtual temperature mean of the layer, as the Rust reader does.
        def tv(k):
            tk = t[k] + 273.15
            e = 6.112 * np.exp(17.67 * td[k] / (td[k] + 243.5))
            return tk * (1.0 + 0.608 * 0.622 * e / (p[k - 1] if k else p[0]))
        p[i] = p[i - 1] * np.exp(-gg * (z[i] - z[i - 1]) / (rd * 0.5 * (tv(i - 1) + tv(i))))
    return p * units.hPa, t * units.degC, td * units.degC


def best_of(f, repeats):
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t0)
    return best


def exact_pseudo(t_lcl, p_lcl, p_levels):
    """MetPy's moist-lapse ODE dT/dp, solved tightly."""
    rd, cp, lv, eps = Rd.m, Cp_d.m, Lv.m, epsilon.m

    def dtdp(p, t):
        rs = mpcalc.saturation_mixing_ratio(p * units.Pa, t * units.K).m
        return (rd * t + lv * rs) / (cp + lv * lv * rs * eps / (rd * t * t)) / p

    sol = solve_ivp(dtdp, (p_lcl, p_levels[-1]), [t_lcl], t_eval=p_levels,
                    rtol=1e-12, atol=1e-10)
    return sol.y[0]


for n in (17, 401, 4001):
    p, t, td = sounding(n)
    def run():
        mpcalc.lcl(p[0], t[0], td[0])
        return mpcalc.parcel_profile(p, t[0], td[0])
    seconds = best_of(run, 5 if n > 1000 else 20)
    prof = run().to("K").m
    p_lcl, t_lcl = mpcalc.lcl(p[0], t[0], td[0])
    p_pa = p.to("Pa").m
    above = p_pa < p_lcl.to("Pa").m
    exact = exact_pseudo(t_lcl.to("K").m, p_lcl.to("Pa").m, p_pa[above])
    # The integration error alone: MetPy's moist_lapse from the LCL.
    # (parcel_profile also starts its moist adiabat from its own dry-kappa
    # adiabat, which adds an offset of a few hundredths of a kelvin.)
    lapse = mpcalc.moist_lapse(p[above], t_lcl, p_lcl).to("K").m
    err = np.max(np.abs(lapse - exact))
    offset = np.max(np.abs(prof[above] - exact))
    print(f"levels={n} metpy_ms={seconds * 1e3:.3f} "
          f"moist_lapse_max_err_K={err:.2e} parcel_profile_max_dev_K={offset:.2e}")
