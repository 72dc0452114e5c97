"""The package's contract: units, shapes, the simulation's columns, and
errors that carry the library's messages."""

import os
import signal
import threading

import numpy as np
import pytest

import cumulus

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BOMEX = os.path.join(ROOT, "scenes", "bomex_sounding.csv")


def test_plain_numbers_are_hpa_and_celsius_and_arrays_broadcast():
    p, t = cumulus.lcl(1000.0, 25.0, 18.0)
    assert isinstance(p, float) and isinstance(t, float)
    assert 880.0 < p < 920.0 and 14.0 < t < 18.0
    ps, ts = cumulus.lcl([1000.0, 950.0], 25.0, [18.0, 10.0])
    assert ps.shape == (2,) and ts.shape == (2,)
    assert ps[0] == pytest.approx(p, abs=1e-9) and ts[0] == pytest.approx(t, abs=1e-9)
    # Drier air condenses higher.
    assert ps[1] < ps[0] - 50.0


def test_pint_quantities_give_quantities_in_hpa_and_kelvin():
    from metpy.units import units
    p, t = cumulus.lcl(100000.0 * units.Pa, 298.15 * units.K, 18.0 * units.degC)
    p_plain, t_plain = cumulus.lcl(1000.0, 25.0, 18.0)
    assert str(p.units) == "hectopascal" and str(t.units) == "kelvin"
    assert p.m == pytest.approx(p_plain, abs=1e-9)
    assert t.m == pytest.approx(t_plain + 273.15, abs=1e-9)
    prof = cumulus.parcel_profile([1000.0, 900.0, 800.0] * units.hPa, 25 * units.degC, 18 * units.degC)
    plain = cumulus.parcel_profile([1000.0, 900.0, 800.0], 25.0, 18.0)
    assert np.allclose(prof.m_as("degC"), plain, atol=1e-9)


def test_the_profile_starts_at_the_air_and_cools_upward():
    p = np.linspace(1000.0, 300.0, 50)
    for adiabat in ("pseudo", "reversible"):
        t = cumulus.parcel_profile(p, 25.0, 18.0, adiabat=adiabat)
        assert t[0] == pytest.approx(25.0, abs=1e-9)
        assert np.all(np.diff(t) < 0.0), adiabat
    # Carried condensate adds its heat capacity to the air's, so the
    # reversible parcel cools more slowly and is warmer aloft.
    rev = cumulus.parcel_profile(p, 25.0, 18.0, adiabat="reversible")
    pseudo = cumulus.parcel_profile(p, 25.0, 18.0)
    assert rev[-1] > pseudo[-1] + 1.0


def test_bad_numbers_name_the_argument_the_index_and_the_units():
    with pytest.raises(ValueError, match=r"pressure\[1\] is -500 Pa \(-5 hPa\)"):
        cumulus.lcl([1000.0, -5.0], 20.0, 10.0)
    with pytest.raises(ValueError, match=r"dewpoint\[0\] is NaN"):
        cumulus.lcl(1000.0, 20.0, float("nan"))
    with pytest.raises(ValueError, match="adiabat"):
        cumulus.parcel_profile([1000.0, 900.0], 20.0, 10.0, adiabat="wet")
    with pytest.raises(ValueError, match="one value each"):
        cumulus.parcel_profile([1000.0, 900.0], [20.0, 19.0], 10.0)


def test_read_sounding_gives_columns_in_hpa_and_celsius():
    s = cumulus.read_sounding(BOMEX)
    assert set(s) == {"height_m", "pressure_hPa", "temperature_C", "dewpoint_C", "mixing_ratio_kgkg"}
    n = len(s["height_m"])
    assert n > 10 and all(len(v) == n for v in s.values())
    assert np.all(np.diff(s["height_m"]) > 0) and np.all(np.diff(s["pressure_hPa"]) < 0)
    assert 1000.0 < s["pressure_hPa"][0] < 1030.0
    assert np.all(s["dewpoint_C"] <= s["temperature_C"] + 1e-9)


def test_lift_sounding_gives_the_profile_columns():
    prof = cumulus.lift_sounding(BOMEX, adiabat="reversible")
    assert prof["parcel_qc_gkg"][0] == 0.0 and prof["parcel_qc_gkg"][-1] > 1.0
    assert 500.0 < prof["lcl_height_m"] < 700.0
    # Total water is conserved on the reversible adiabat.
    qt = prof["parcel_qv_gkg"] + prof["parcel_qc_gkg"]
    assert np.allclose(qt, qt[0], rtol=1e-9)


def test_library_errors_carry_the_command_lines_messages(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text(
        "height_m,pressure_hPa,temperature_C,dewpoint_C\n0,1000,20,10\n100,,19,oops\n"
    )
    with pytest.raises(cumulus.SoundingError, match=r"bad\.csv:3: .*dewpoint_C"):
        cumulus.read_sounding(bad)
    with pytest.raises(cumulus.SoundingError, match="cannot read sounding"):
        cumulus.lift_sounding(tmp_path / "missing.csv")
    scene = tmp_path / "s.toml"
    scene.write_text('[physics]\ndt_s = 5.0\nparcels = "many"\n')
    with pytest.raises(cumulus.SceneError, match=r"s\.toml:3:\d+: .*parcels"):
        cumulus.simulate(scene, 10.0)
    with pytest.raises(cumulus.SceneError, match="physics.dt_s"):
        cumulus.simulate("fair_weather", 10.0, dt_s=-1.0)
    with pytest.raises(cumulus.SceneError, match="no built-in scene"):
        cumulus.simulate("no_such_scene", 10.0)
    assert issubclass(cumulus.SoundingError, cumulus.CumulusError)
    assert issubclass(cumulus.SceneError, cumulus.CumulusError)
    # Tracebacks name them as the package exports them.
    assert cumulus.SceneError.__module__ == "cumulus"


def test_simulate_returns_the_parcel_curves_columns():
    runs = cumulus.simulate("fair_weather", 60.0, dt_s=5.0, parcels=40, seed=7, every_s=30.0)
    names = list(runs)
    assert names[:7] == ["t_s", "id", "generation", "age_s", "x_m", "y_m", "z_m"]
    assert names[-1] == "coverage" and len(names) == 19
    # Records at 0, 30 and 60 s, one row per parcel each.
    assert np.array_equal(np.unique(runs["t_s"]), [0.0, 30.0, 60.0])
    assert all(v.shape == (3 * 40,) and v.dtype == np.float64 for v in runs.values())
    assert np.array_equal(runs["id"][:40], np.arange(40))
    again = cumulus.simulate("fair_weather", 60.0, dt_s=5.0, parcels=40, seed=7, every_s=30.0)
    assert all(np.array_equal(runs[k], again[k]) for k in runs)
    other = cumulus.simulate("fair_weather", 60.0, dt_s=5.0, parcels=40, seed=8, every_s=30.0)
    assert not np.array_equal(runs["x_m"], other["x_m"])


def test_simulate_reads_a_sounding_in_place_of_the_scenes_atmosphere():
    plain = cumulus.simulate("fair_weather", 600.0, parcels=30, seed=1, every_s=600.0)
    bomex = cumulus.simulate("fair_weather", 600.0, parcels=30, seed=1, every_s=600.0, sounding=BOMEX)
    assert not np.array_equal(plain["theta_v_env_K"], bomex["theta_v_env_K"])


def test_ctrl_c_stops_a_simulation():
    # SIGINT after the run has started: the frame loop checks for signals.
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            cumulus.simulate("fair_weather", 1.0e7, parcels=2000, every_s=1.0e7)
    finally:
        timer.cancel()
