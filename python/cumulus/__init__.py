"""cumulus' parcel physics for Python.

The same code as the ``cumulus`` command line and Rust crate: the lifting
condensation level, parcels lifted without mixing (pseudo- or reversible
adiabat), soundings in every format cumulus reads, and the SPH parcel
simulation of a scene.

Arguments come in MetPy's order. Units:

* plain numbers (floats, lists, numpy arrays): pressure in hPa,
  temperature and dewpoint in degrees Celsius; results in the same units;
* pint quantities (MetPy's ``units``): converted from whatever units they
  carry; results are quantities of the same registry, pressure in hPa and
  temperature in kelvin (as MetPy returns them).

Errors the library finds are raised as :class:`SoundingError` or
:class:`SceneError` (both :class:`CumulusError`) with the message the
command line prints, naming the file, line and key; numbers out of their
domain raise :class:`ValueError` naming the argument and the index.
"""

import os

import numpy as np

from . import _native
from ._native import CumulusError, SceneError, SoundingError

__all__ = [
    "CumulusError",
    "SceneError",
    "SoundingError",
    "lcl",
    "lift_sounding",
    "parcel_profile",
    "read_sounding",
    "simulate",
]
__version__ = "0.1.0"

_ZERO_CELSIUS_K = 273.15


def _is_quantity(x):
    return hasattr(x, "units") and hasattr(x, "to") and hasattr(x, "magnitude")


def _registry(*xs):
    """The pint registry of the first quantity among ``xs``, else None."""
    for x in xs:
        if _is_quantity(x):
            return x._REGISTRY
    return None


def _pressure_pa(x):
    if _is_quantity(x):
        return np.asarray(x.to("Pa").magnitude, dtype=np.float64)
    return np.asarray(x, dtype=np.float64) * 100.0


def _temperature_k(x):
    if _is_quantity(x):
        return np.asarray(x.to("K").magnitude, dtype=np.float64)
    return np.asarray(x, dtype=np.float64) + _ZERO_CELSIUS_K


def _pressure_out(pa, reg):
    hpa = np.asarray(pa) / 100.0
    return reg.Quantity(hpa, "hPa") if reg is not None else hpa


def _temperature_out(k, reg):
    k = np.asarray(k)
    return reg.Quantity(k, "K") if reg is not None else k - _ZERO_CELSIUS_K


def _scalar_if(value, scalar):
    if not scalar:
        return value
    if _is_quantity(value):
        return value[()]
    return float(np.asarray(value)[()])


def _flat(a):
    return np.ascontiguousarray(np.ravel(a), dtype=np.float64)


def lcl(pressure, temperature, dewpoint):
    """The lifting condensation level of air at ``pressure``,
    ``temperature`` and ``dewpoint`` (MetPy's ``lcl``).

    The air follows its own unsaturated adiabat, with the gas constant and
    heat capacity of the moist air, until it meets the dewpoint of its
    conserved mixing ratio (Romps 2017, as MetPy since 1.6). Arrays are
    taken elementwise (numpy broadcasting).

    Returns ``(pressure, temperature)`` of the LCL: floats for scalar
    input, else arrays of the broadcast shape.
    """
    reg = _registry(pressure, temperature, dewpoint)
    p, t, td = np.broadcast_arrays(
        _pressure_pa(pressure), _temperature_k(temperature), _temperature_k(dewpoint)
    )
    shape = p.shape
    lp, lt = _native.lcl(_flat(p), _flat(t), _flat(td))
    lp, lt = lp.reshape(shape), lt.reshape(shape)
    scalar = shape == ()
    return (
        _scalar_if(_pressure_out(lp, reg), scalar),
        _scalar_if(_temperature_out(lt, reg), scalar),
    )


def parcel_profile(pressure, temperature, dewpoint, adiabat="pseudo"):
    """The temperature of air lifted from ``pressure[0]`` without mixing,
    at every level of ``pressure`` (MetPy's ``parcel_profile``).

    ``temperature`` and ``dewpoint`` are the air's at ``pressure[0]``.
    Below the LCL the air follows the unsaturated adiabat of the moist air
    (MetPy uses the dry one there, about 0.1 K colder at the LCL); above,
    ``adiabat="pseudo"`` (condensate falls out, MetPy's ``moist_lapse``) or
    ``"reversible"`` (condensate carried; total water and moist entropy
    conserved).
    """
    reg = _registry(pressure, temperature, dewpoint)
    p = _flat(_pressure_pa(pressure))
    t0 = _temperature_k(temperature)
    td0 = _temperature_k(dewpoint)
    if t0.size != 1 or td0.size != 1:
        raise ValueError(
            "temperature and dewpoint are the lifted air's, one value each "
            f"(got {t0.size} and {td0.size})"
        )
    out = _native.parcel_profile(p, float(t0.ravel()[0]), float(td0.ravel()[0]), adiabat)
    return _temperature_out(out["t_k"], reg)


def _surface_pa(surface_pressure):
    return float(np.ravel(_pressure_pa(surface_pressure))[0])


def read_sounding(path, surface_pressure=1013.25):
    """A sounding file in any format cumulus reads: its CSV
    (``height_m,pressure_hPa,temperature_C,dewpoint_C`` or
    ``relative_humidity_pct``), University of Wyoming text, SHARPpy or
    IGRA2, recognised by content.

    Missing pressures are filled hydrostatically, anchored at
    ``surface_pressure`` (hPa) when no level gives one. Returns a dict of
    arrays: ``height_m``, ``pressure_hPa``, ``temperature_C``,
    ``dewpoint_C`` (NaN for air without vapour) and ``mixing_ratio_kgkg``.
    """
    c = _native.read_sounding(os.fspath(path), _surface_pa(surface_pressure))
    return {
        "height_m": c["height_m"],
        "pressure_hPa": c["pressure_pa"] / 100.0,
        "temperature_C": c["temperature_k"] - _ZERO_CELSIUS_K,
        "dewpoint_C": c["dewpoint_k"] - _ZERO_CELSIUS_K,
        "mixing_ratio_kgkg": c["mixing_ratio"],
    }


def lift_sounding(path, adiabat="pseudo", surface_pressure=1013.25):
    """The sounding's lowest air lifted without mixing through its levels,
    as ``cumulus profile`` computes it.

    Returns a dict: the columns of ``cumulus profile --out`` (``height_m``,
    ``pressure_hPa``, ``env_T_K``, ``parcel_T_K``, ``parcel_qv_gkg``,
    ``parcel_qc_gkg``, ``buoyancy_mps2``) as arrays, and the floats
    ``lcl_pressure_hPa``, ``lcl_temperature_K`` and ``lcl_height_m`` (NaN
    when the air does not saturate within the sounding).
    """
    c = _native.lift_sounding(os.fspath(path), adiabat, _surface_pa(surface_pressure))
    return {
        "height_m": c["height_m"],
        "pressure_hPa": c["pressure_pa"] / 100.0,
        "env_T_K": c["env_t_k"],
        "parcel_T_K": c["parcel_t_k"],
        "parcel_qv_gkg": c["parcel_qv"] * 1e3,
        "parcel_qc_gkg": c["parcel_qc"] * 1e3,
        "buoyancy_mps2": c["buoyancy_mps2"],
        "lcl_pressure_hPa": c["lcl_p_pa"] / 100.0,
        "lcl_temperature_K": c["lcl_t_k"],
        "lcl_height_m": c["lcl_height_m"],
    }


def simulate(
    scene,
    duration_s=3600.0,
    *,
    dt_s=None,
    parcels=None,
    seed=None,
    every_s=None,
    sounding=None,
):
    """Runs a scene's SPH parcel simulation, as ``cumulus simulate`` does.

    ``scene`` is a scene TOML file or the name of a shipped scene
    (``"fair_weather"``, ``"bomex"``, ...). ``dt_s``, ``parcels`` and
    ``seed`` override the scene's ``physics.dt_s``, ``physics.parcels`` and
    ``physics.seed`` and are checked as those keys; ``sounding`` replaces
    the scene's atmosphere with a sounding file. Records are taken at the
    start and every ``every_s`` simulated seconds (default: every frame),
    and at the end.

    Returns a dict of arrays, one entry per parcel per record, with the
    columns of ``cumulus simulate --out`` (docs/physics.md, "Parcel
    curves"): ``t_s``, ``id``, ``generation``, ``age_s``, ``x_m``, ``y_m``,
    ``z_m`` (height), ``w_mps``, ``theta_v_K``, ``theta_v_env_K``, ``T_K``,
    ``qv_gkg``, ``qc_gkg``, ``qt_gkg``, ``buoyancy_mps2``,
    ``condensed_fraction``, ``fill``, ``z_norm``, ``coverage``. The GIL is
    released while it steps; Ctrl-C stops it with ``KeyboardInterrupt``.
    """
    return _native.simulate(
        os.fspath(scene),
        float(duration_s),
        dt_s=None if dt_s is None else float(dt_s),
        parcels=parcels,
        seed=seed,
        every_s=None if every_s is None else float(every_s),
        sounding=None if sounding is None else os.fspath(sounding),
    )
