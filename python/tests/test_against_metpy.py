"""The Python package against MetPy 1.7.1, computed here in-process on the
soundings the Rust tests use (tests/data), with the Rust tests' tolerances
(tests/physics_reference.rs)."""

import glob
import math
import os

import numpy as np
import pytest

import cumulus

# MetPy is the reference: without it these tests fail, they do not skip
# (`pip install './python[test]'`).
import metpy.calc as mpcalc  # noqa: E402
from metpy.units import units  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SOUNDINGS = sorted(
    [os.path.join(ROOT, "scenes", "bomex_sounding.csv")]
    + glob.glob(os.path.join(ROOT, "tests", "data", "*.csv"))
    + glob.glob(os.path.join(ROOT, "tests", "data", "surface", "*.csv"))
)
# tests/physics_reference.rs: the LCL within 0.1 hPa and 0.003 K of
# MetPy's on every sounding; the pseudo-adiabat within 0.2 K up to 3 km
# above the LCL (0.1 K below 48 degC).
LCL_PRESSURE_HPA = 0.1
LCL_TEMPERATURE_K = 0.003
PSEUDO_K = 0.2
PSEUDO_BELOW_48_C_K = 0.1


def surface(path):
    s = cumulus.read_sounding(path)
    return s, s["pressure_hPa"][0], s["temperature_C"][0], s["dewpoint_C"][0]


def test_there_are_soundings_to_compare():
    assert len(SOUNDINGS) >= 15, SOUNDINGS


@pytest.mark.parametrize("path", SOUNDINGS, ids=os.path.basename)
def test_lcl_matches_metpy(path):
    _, p, t, td = surface(path)
    p_ref, t_ref = mpcalc.lcl(p * units.hPa, t * units.degC, td * units.degC)
    p_lcl, t_lcl = cumulus.lcl(p, t, td)
    assert abs(p_lcl - p_ref.m_as("hPa")) < LCL_PRESSURE_HPA
    assert abs((t_lcl + 273.15) - t_ref.m_as("K")) < LCL_TEMPERATURE_K


@pytest.mark.parametrize("path", SOUNDINGS, ids=os.path.basename)
def test_pseudo_profile_matches_metpy_to_3_km_above_the_lcl(path):
    s, p, t, td = surface(path)
    levels = s["pressure_hPa"] * units.hPa
    ref = mpcalc.parcel_profile(levels, t * units.degC, td * units.degC).m_as("K")
    ours = cumulus.parcel_profile(levels, t * units.degC, td * units.degC).m_as("K")
    p_lcl, _ = cumulus.lcl(p, t, td)
    z_lcl = np.interp(-math.log(p_lcl), -np.log(s["pressure_hPa"]), s["height_m"])
    near = s["height_m"] <= z_lcl + 3000.0
    assert near.sum() >= 5
    worst = np.max(np.abs(ours - ref)[near])
    tolerance = PSEUDO_K if t >= 45.0 else PSEUDO_BELOW_48_C_K
    assert worst < tolerance, f"{worst:.4f} K"


def test_reversible_profile_matches_the_exact_adiabat():
    # tests/reference/reversible_deep_tropical.csv: Emanuel's reversible
    # adiabat solved with MetPy's constants (reversible_reference.py).
    path = os.path.join(ROOT, "tests", "reference", "reversible_deep_tropical.csv")
    rows = [line.split(",") for line in open(path) if not line.startswith(("#", "height"))]
    ref_z = np.array([float(r[0]) for r in rows])
    ref_t = np.array([float(r[2]) for r in rows])
    prof = cumulus.lift_sounding(
        os.path.join(ROOT, "tests", "data", "deep_tropical.csv"), adiabat="reversible"
    )
    ours = np.interp(ref_z, prof["height_m"], prof["parcel_T_K"])
    on_level = np.isin(ref_z, prof["height_m"])
    assert on_level.sum() >= 10
    # tests/physics_reference.rs: REVERSIBLE_TOLERANCE_K.
    assert np.max(np.abs(ours - ref_t)[on_level]) < 0.025


def test_lcl_height_matches_metpys_on_the_same_levels():
    path = os.path.join(ROOT, "scenes", "bomex_sounding.csv")
    s, p, t, td = surface(path)
    p_ref, _ = mpcalc.lcl(p * units.hPa, t * units.degC, td * units.degC)
    z_ref = np.interp(-math.log(p_ref.m_as("hPa")), -np.log(s["pressure_hPa"]), s["height_m"])
    prof = cumulus.lift_sounding(path)
    # tests/physics_reference.rs: LCL_HEIGHT_TOLERANCE_M.
    assert abs(prof["lcl_height_m"] - z_ref) < 0.7


def test_every_sounding_format_reads_like_the_csv():
    csv = cumulus.read_sounding(os.path.join(ROOT, "scenes", "bomex_sounding.csv"))
    for name in ("bomex_wyoming.txt", "bomex_sharppy.txt", "bomex_igra2.txt"):
        other = cumulus.read_sounding(os.path.join(ROOT, "tests", "data", "formats", name))
        assert other["height_m"].shape == csv["height_m"].shape, name
        # tests/sounding_formats.rs: the loosest of the three formats.
        assert np.max(np.abs(other["pressure_hPa"] - csv["pressure_hPa"])) <= 0.05, name
        assert np.max(np.abs(other["height_m"] - csv["height_m"])) <= 0.5, name
        assert np.max(np.abs(other["temperature_C"] - csv["temperature_C"])) <= 0.1, name
