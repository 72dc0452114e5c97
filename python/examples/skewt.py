#!/usr/bin/env python3
"""A sounding and the air lifted from its lowest level, on MetPy's Skew-T.

    pip install ./python metpy matplotlib
    python python/examples/skewt.py --sounding scenes/deep_tropical_sounding.csv --out skewt.png

The sounding may be in any format cumulus reads. cumulus' pseudo-adiabatic
and reversible parcels are drawn over MetPy's own ``parcel_profile``, with
cumulus' LCL marked; the shaded area is the pseudo-adiabatic parcel's
CAPE.
"""

import argparse
import os
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import metpy.calc as mpcalc  # noqa: E402
from metpy.plots import SkewT  # noqa: E402
from metpy.units import units  # noqa: E402

import cumulus  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_SOUNDING = os.path.join(HERE, "..", "..", "scenes", "deep_tropical_sounding.csv")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sounding", default=DEFAULT_SOUNDING, help="sounding file (any format cumulus reads)")
    ap.add_argument("--out", default="skewt.png", help="PNG to write (atomically)")
    args = ap.parse_args()

    s = cumulus.read_sounding(args.sounding)
    p = s["pressure_hPa"] * units.hPa
    t = s["temperature_C"] * units.degC
    td = s["dewpoint_C"] * units.degC

    pseudo = cumulus.parcel_profile(p, t[0], td[0]).to("degC")
    reversible = cumulus.parcel_profile(p, t[0], td[0], adiabat="reversible").to("degC")
    metpy_parcel = mpcalc.parcel_profile(p, t[0], td[0]).to("degC")
    p_lcl, t_lcl = cumulus.lcl(p[0], t[0], td[0])

    fig = plt.figure(figsize=(7, 7), dpi=110)
    skew = SkewT(fig, rotation=45)
    skew.plot(p, t, "tab:red", label="sounding: temperature")
    skew.plot(p, td, "tab:green", label="sounding: dewpoint")
    skew.plot(p, metpy_parcel, color="0.6", linewidth=5, alpha=0.6, label="MetPy parcel_profile")
    skew.plot(p, pseudo, "k", linewidth=1.4, label="cumulus: pseudo-adiabatic parcel")
    skew.plot(p, reversible, "k--", linewidth=1.2, label="cumulus: reversible parcel")
    skew.plot(p_lcl, t_lcl.to("degC"), "ko", markerfacecolor="white", label="cumulus: LCL")
    skew.shade_cape(p, t, pseudo)
    skew.plot_dry_adiabats(alpha=0.25)
    skew.plot_moist_adiabats(alpha=0.25)
    skew.plot_mixing_lines(alpha=0.25)
    skew.ax.set_ylim(p.m.max() + 10.0, 100.0)
    skew.ax.set_xlim(-40, 45)
    skew.ax.legend(loc="lower left", fontsize=8)
    skew.ax.set_title(os.path.basename(args.sounding))

    out = os.path.abspath(args.out)
    fd, tmp = tempfile.mkstemp(suffix=".png", dir=os.path.dirname(out))
    os.close(fd)
    try:
        fig.savefig(tmp)
        os.replace(tmp, out)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
