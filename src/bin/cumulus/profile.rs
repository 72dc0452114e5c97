//! `cumulus profile`: lift the sounding's lowest air without mixing (like
//! MetPy's `parcel_profile`).

use std::path::PathBuf;

use anyhow::{Context, Result, bail};

use cumulus::io::write_atomically;
use cumulus::sim::Sounding;
use cumulus::sim::lift::{Adiabat, lift_sounding};

#[derive(clap::Args)]
#[command(
    after_help = "Example:\n  cumulus profile --sounding scenes/bomex_sounding.csv --adiabat reversible --out profile.csv"
)]
pub struct ProfileArgs {
    /// Sounding CSV (height_m,pressure_hPa,temperature_C,dewpoint_C).
    #[arg(long)]
    sounding: PathBuf,
    /// Moist adiabat above the LCL: pseudo (condensate removed) or reversible.
    #[arg(long, value_enum, default_value_t = AdiabatArg::Pseudo)]
    adiabat: AdiabatArg,
    /// Ground pressure in hPa, used when the sounding gives no pressures.
    #[arg(long, default_value_t = 1013.25)]
    surface_pressure_hpa: f64,
    /// Output CSV, one row per sounding level (written atomically).
    #[arg(long)]
    out: Option<PathBuf>,
}

/// `--adiabat` (kept here so the simulator does not depend on clap).
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum AdiabatArg {
    /// Condensate removed as it forms (meteorologists' default).
    Pseudo,
    /// Condensate carried with the parcel.
    Reversible,
}

pub fn run(a: ProfileArgs) -> Result<()> {
    if !(300.0..=1100.0).contains(&a.surface_pressure_hpa) {
        bail!(
            "--surface-pressure-hpa is {}, expected 300..=1100",
            a.surface_pressure_hpa
        );
    }
    let s = Sounding::load(&a.sounding, a.surface_pressure_hpa * 100.0)?;
    let adiabat = match a.adiabat {
        AdiabatArg::Pseudo => Adiabat::Pseudo,
        AdiabatArg::Reversible => Adiabat::Reversible,
    };
    let prof = lift_sounding(&s, adiabat);
    if prof.lcl.pressure_pa > 0.0 {
        // MetPy's `lcl` too gives the pressure and temperature where the
        // lifted air saturates, within the sounding or above its top.
        println!("lcl_pressure_hPa={:.3}", prof.lcl.pressure_pa / 100.0);
        println!("lcl_temperature_K={:.3}", prof.lcl.temperature_k);
    } else {
        // Air without vapour never saturates: no LCL at all (it printed 0
        // hPa and 0 K).
        let why = "(the lowest level's air holds no water vapour: it never saturates)";
        println!("lcl_pressure_hPa=none {why}");
        println!("lcl_temperature_K=none {why}");
    }
    match (prof.lcl_height_m, prof.rows.last()) {
        (Some(z), _) => println!("lcl_height_m={z:.1}"),
        (None, Some(top)) if prof.lcl.pressure_pa > 0.0 => println!(
            "lcl_height_m=none (the LCL lies above the sounding's top, {:.1} hPa at {:.0} m)",
            top.pressure_pa / 100.0,
            top.height_m
        ),
        (None, _) => {
            println!("lcl_height_m=none (the parcel does not saturate within the sounding)")
        }
    }
    if let Some(out) = &a.out {
        crate::refuse_overwriting_inputs(out, &[("sounding", a.sounding.clone())])?;
        crate::guard_output_file(out);
        write_atomically(out, |w| {
            writeln!(
                w,
                "height_m,pressure_hPa,env_T_K,parcel_T_K,parcel_qv_gkg,parcel_qc_gkg,buoyancy_mps2"
            )?;
            for r in &prof.rows {
                writeln!(
                    w,
                    "{:.3},{:.4},{:.4},{:.4},{:.5},{:.5},{:.6}",
                    r.height_m,
                    r.pressure_pa / 100.0,
                    r.env_t_k,
                    r.parcel_t_k,
                    r.parcel_qv * 1e3,
                    r.parcel_qc * 1e3,
                    r.buoyancy
                )?;
            }
            Ok(())
        })
        .with_context(|| format!("{}: cannot write profile", out.display()))?;
    }
    Ok(())
}
