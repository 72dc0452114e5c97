//! `cumulus._native`: the parcel physics for Python, in SI units (Pa, K,
//! kg/kg, m, s). The `cumulus` package (`python/cumulus/__init__.py`)
//! wraps it in MetPy's argument order and units; this layer only checks
//! the numbers, calls the library and turns its errors into exceptions
//! that carry the library's own messages.

use std::path::{Path, PathBuf};

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use cumulus::scene::{Method, Scene, SceneError as SceneFault};
use cumulus::sim::constants::ZERO_CELSIUS_K;
use cumulus::sim::lift::{Adiabat, lcl as lcl_of, lift_parcel, lift_sounding as lift};
use cumulus::sim::sounding::Level;
use cumulus::sim::thermo::{dewpoint, mixing_ratio_from_dewpoint};
use cumulus::sim::{
    Band, FramePlan, ParcelRecord, Simulation, Sounding, SoundingError as SoundingFault,
};

create_exception!(
    cumulus,
    CumulusError,
    PyException,
    "Every error cumulus raises."
);
create_exception!(
    cumulus,
    SoundingError,
    CumulusError,
    "A sounding that cannot be read: the message names the file and line."
);
create_exception!(
    cumulus,
    SceneError,
    CumulusError,
    "A scene that cannot be read or run: the message names the file, line and key."
);

fn sounding_error(e: SoundingFault) -> PyErr {
    SoundingError::new_err(e.to_string())
}

fn scene_error(e: SceneFault) -> PyErr {
    match e {
        SceneFault::Sounding(s) => sounding_error(s),
        e => SceneError::new_err(e.to_string()),
    }
}

/// `name[i]` of the first value outside `ok`, as a `ValueError` that gives
/// it in SI and in the units plain numbers take (`shown`).
fn check(
    name: &str,
    values: &[f64],
    ok: impl Fn(f64) -> bool,
    want: &str,
    shown: impl Fn(f64) -> String,
) -> PyResult<()> {
    match values.iter().position(|&x| !(x.is_finite() && ok(x))) {
        None => Ok(()),
        Some(i) => Err(PyValueError::new_err(format!(
            "{name}[{i}] is {}: expected a finite value {want}",
            shown(values[i])
        ))),
    }
}

fn check_pressures(name: &str, p: &[f64]) -> PyResult<()> {
    let shown = |x: f64| format!("{x} Pa ({} hPa)", x / 100.0);
    check(
        name,
        p,
        |x| x > 0.0 && x <= 200_000.0,
        "in (0, 2000] hPa",
        shown,
    )
}

fn check_temperatures(name: &str, t: &[f64]) -> PyResult<()> {
    let shown = |x: f64| format!("{x} K ({} °C)", x - ZERO_CELSIUS_K);
    check(
        name,
        t,
        |x| (100.0..=400.0).contains(&x),
        "in 100..=400 K",
        shown,
    )
}

fn adiabat(name: &str) -> PyResult<Adiabat> {
    match name {
        "pseudo" => Ok(Adiabat::Pseudo),
        "reversible" => Ok(Adiabat::Reversible),
        other => Err(PyValueError::new_err(format!(
            "adiabat is {other:?}: expected \"pseudo\" or \"reversible\""
        ))),
    }
}

/// A numpy float array owned by Python.
type Array<'py> = Bound<'py, PyArray1<f64>>;

fn array<'py>(py: Python<'py>, v: Vec<f64>) -> Array<'py> {
    PyArray1::from_vec(py, v)
}

/// Columns as a dict of float arrays, in the given order.
fn columns<'py>(py: Python<'py>, cols: Vec<(&str, Vec<f64>)>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, v) in cols {
        d.set_item(name, array(py, v))?;
    }
    Ok(d)
}

/// The LCL of each `(p, t, td)`, elementwise (equal lengths): pressures
/// (Pa) and temperatures (K).
#[pyfunction]
fn lcl<'py>(
    py: Python<'py>,
    p_pa: PyReadonlyArray1<'py, f64>,
    t_k: PyReadonlyArray1<'py, f64>,
    td_k: PyReadonlyArray1<'py, f64>,
) -> PyResult<(Array<'py>, Array<'py>)> {
    let (p, t, td) = (p_pa.as_slice()?, t_k.as_slice()?, td_k.as_slice()?);
    if p.len() != t.len() || p.len() != td.len() {
        return Err(PyValueError::new_err(format!(
            "pressure, temperature and dewpoint have {}, {} and {} values: expected equal lengths",
            p.len(),
            t.len(),
            td.len()
        )));
    }
    check_pressures("pressure", p)?;
    check_temperatures("temperature", t)?;
    check_temperatures("dewpoint", td)?;
    let (mut lp, mut lt) = (Vec::with_capacity(p.len()), Vec::with_capacity(p.len()));
    for i in 0..p.len() {
        let l = lcl_of(t[i], mixing_ratio_from_dewpoint(td[i], p[i]), p[i]);
        lp.push(l.pressure_pa);
        lt.push(l.temperature_k);
    }
    Ok((array(py, lp), array(py, lt)))
}

/// Air at `p_pa[0]`, `t0_k`, dewpoint `td0_k` lifted without mixing
/// through `p_pa`: `t_k`, `qv`, `qc` per level and the LCL's `lcl_p_pa`,
/// `lcl_t_k`.
#[pyfunction]
fn parcel_profile<'py>(
    py: Python<'py>,
    p_pa: PyReadonlyArray1<'py, f64>,
    t0_k: f64,
    td0_k: f64,
    adiabat_name: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let p = p_pa.as_slice()?;
    if p.is_empty() {
        return Err(PyValueError::new_err(
            "pressure is empty: expected the levels, the parcel's own first",
        ));
    }
    check_pressures("pressure", p)?;
    check_temperatures("temperature", &[t0_k])?;
    check_temperatures("dewpoint", &[td0_k])?;
    let how = adiabat(adiabat_name)?;
    let qv0 = mixing_ratio_from_dewpoint(td0_k, p[0]);
    let p = p.to_vec();
    let lifted = py.detach(|| lift_parcel(t0_k, qv0, p[0], &p, how));
    let d = columns(
        py,
        vec![
            ("t_k", lifted.levels.iter().map(|l| l.t_k).collect()),
            ("qv", lifted.levels.iter().map(|l| l.qv).collect()),
            ("qc", lifted.levels.iter().map(|l| l.qc).collect()),
        ],
    )?;
    d.set_item("lcl_p_pa", lifted.lcl.pressure_pa)?;
    d.set_item("lcl_t_k", lifted.lcl.temperature_k)?;
    Ok(d)
}

fn load_sounding(path: &Path, surface_pressure_pa: f64) -> PyResult<Sounding> {
    check_pressures("surface_pressure", &[surface_pressure_pa])?;
    Sounding::load(path, surface_pressure_pa).map_err(sounding_error)
}

/// A sounding file in any supported format (CSV, University of Wyoming
/// text, SHARPpy, IGRA2), its levels as columns: `height_m`,
/// `pressure_pa`, `temperature_k`, `dewpoint_k` (NaN for dry air) and
/// `mixing_ratio` (kg/kg).
#[pyfunction]
fn read_sounding<'py>(
    py: Python<'py>,
    path: PathBuf,
    surface_pressure_pa: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let s = load_sounding(&path, surface_pressure_pa)?;
    let lv = s.levels();
    let p = |l: &Level| l.pressure_pa.unwrap_or(f64::NAN);
    columns(
        py,
        vec![
            ("height_m", lv.iter().map(|l| l.height_m).collect()),
            ("pressure_pa", lv.iter().map(p).collect()),
            (
                "temperature_k",
                lv.iter().map(|l| l.temperature_k).collect(),
            ),
            (
                "dewpoint_k",
                lv.iter()
                    .map(|l| dewpoint(l.mixing_ratio, p(l)).unwrap_or(f64::NAN))
                    .collect(),
            ),
            ("mixing_ratio", lv.iter().map(|l| l.mixing_ratio).collect()),
        ],
    )
}

/// The sounding's lowest air lifted through its levels (`cumulus
/// profile`): the columns of the profile and the LCL's `lcl_p_pa`,
/// `lcl_t_k`, `lcl_height_m` (NaN when the air does not saturate within
/// the sounding).
#[pyfunction]
fn lift_sounding<'py>(
    py: Python<'py>,
    path: PathBuf,
    adiabat_name: &str,
    surface_pressure_pa: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let how = adiabat(adiabat_name)?;
    let s = load_sounding(&path, surface_pressure_pa)?;
    let prof = py.detach(|| lift(&s, how));
    let r = &prof.rows;
    let d = columns(
        py,
        vec![
            ("height_m", r.iter().map(|x| x.height_m).collect()),
            ("pressure_pa", r.iter().map(|x| x.pressure_pa).collect()),
            ("env_t_k", r.iter().map(|x| x.env_t_k).collect()),
            ("parcel_t_k", r.iter().map(|x| x.parcel_t_k).collect()),
            ("parcel_qv", r.iter().map(|x| x.parcel_qv).collect()),
            ("parcel_qc", r.iter().map(|x| x.parcel_qc).collect()),
            ("buoyancy_mps2", r.iter().map(|x| x.buoyancy).collect()),
        ],
    )?;
    d.set_item("lcl_p_pa", prof.lcl.pressure_pa)?;
    d.set_item("lcl_t_k", prof.lcl.temperature_k)?;
    d.set_item("lcl_height_m", prof.lcl_height_m.unwrap_or(f64::NAN))?;
    Ok(d)
}

/// The parcel records' columns ([`ParcelRecord::COLUMNS`]), filled one
/// output step at a time.
struct Records {
    cols: Vec<Vec<f64>>,
}

impl Records {
    fn new() -> Self {
        Self {
            cols: vec![Vec::new(); ParcelRecord::COLUMNS.len()],
        }
    }

    fn push(&mut self, sim: &Simulation, band: Band) {
        for r in sim.records(band) {
            for (col, v) in self.cols.iter_mut().zip(r.values()) {
                col.push(v);
            }
        }
    }
}

/// Runs a scene's parcel simulation (`cumulus simulate`): `scene` is a
/// scene file or the name of a shipped scene; the keyword overrides are
/// checked as the scene keys they set. Returns the parcel records of every
/// output step as columns, named and scaled as `cumulus simulate`'s CSV.
#[pyfunction]
#[pyo3(signature = (scene, duration_s, dt_s=None, parcels=None, seed=None, every_s=None, sounding=None))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    scene: PathBuf,
    duration_s: f64,
    dt_s: Option<f64>,
    parcels: Option<usize>,
    seed: Option<u64>,
    every_s: Option<f64>,
    sounding: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let (mut sc, _) = Scene::load_or_builtin(&scene).map_err(scene_error)?;
    if let Some(dt) = dt_s {
        sc.physics.dt_s = dt;
    }
    if let Some(n) = parcels {
        sc.physics.parcels = n;
    }
    if let Some(s) = seed {
        sc.physics.seed = s;
    }
    sc.validate().map_err(scene_error)?;
    if sc.simulation.method == Method::Automaton {
        return Err(SceneError::new_err(format!(
            "{}: simulation.method = \"automaton\" has no parcels to simulate",
            scene.display()
        )));
    }
    for (name, v) in [("duration_s", Some(duration_s)), ("every_s", every_s)] {
        if let Some(v) = v
            && !(v.is_finite() && v > 0.0)
        {
            return Err(PyValueError::new_err(format!(
                "{name} is {v}: expected a finite number > 0"
            )));
        }
    }
    let atm = sc.atmosphere(sounding.as_deref()).map_err(scene_error)?;
    let band = sc.band(&atm);
    let plan = FramePlan::new(duration_s, sc.physics.dt_s);
    let every = every_s.unwrap_or(sc.physics.dt_s);
    let frames = plan.frames();
    let mut sim = Simulation::new(sc.physics.clone(), atm);
    let mut out = Records::new();
    out.push(&sim, band);
    for f in 1..=frames {
        let dt = plan.frame_s(f - 1);
        py.detach(|| sim.advance(dt));
        if plan.records_after(f, every) {
            out.push(&sim, band);
        }
        // Ctrl-C stops the run with KeyboardInterrupt.
        py.check_signals()?;
    }
    columns(
        py,
        ParcelRecord::COLUMNS.into_iter().zip(out.cols).collect(),
    )
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("CumulusError", py.get_type::<CumulusError>())?;
    m.add("SoundingError", py.get_type::<SoundingError>())?;
    m.add("SceneError", py.get_type::<SceneError>())?;
    m.add_function(wrap_pyfunction!(lcl, m)?)?;
    m.add_function(wrap_pyfunction!(parcel_profile, m)?)?;
    m.add_function(wrap_pyfunction!(read_sounding, m)?)?;
    m.add_function(wrap_pyfunction!(lift_sounding, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    Ok(())
}
