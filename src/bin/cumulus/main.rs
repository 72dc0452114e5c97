//! `cumulus`: the command line, one module per command (`simulate.rs`,
//! `profile.rs`, `convergence.rs`, `render.rs`, `bench.rs`, `stats.rs`,
//! `export.rs`;
//! `scene check`
//! is here). Units are in every flag's name and help text. Errors leave
//! through `anyhow` with the file, line or field. This is the binary's
//! edge: the only place that reads the environment (`WGPU_BACKEND`) and
//! sets exit codes.

mod bench;
mod convergence;
mod export;
mod profile;
mod render;
mod simulate;
mod stats;

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use cumulus::scene::Scene;

#[derive(Parser)]
#[command(
    name = "cumulus",
    version,
    about = "Physics-driven cumulus clouds (Goswami, STAG 2019): parcel simulator and tools"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a scene and write the parcel curves (paper's Fig. 5) as CSV.
    #[command(allow_negative_numbers = true)]
    Simulate(simulate::SimulateArgs),
    /// Lift the sounding's lowest air without mixing (like MetPy's
    /// parcel_profile): print its LCL, write one row per level.
    #[command(allow_negative_numbers = true)]
    Profile(profile::ProfileArgs),
    /// Error against run time: run a scene at steps from 0.1 s to 600 s
    /// against a fine reference; write convergence.csv and convergence.png.
    #[command(allow_negative_numbers = true)]
    Convergence(convergence::ConvergenceArgs),
    /// Simulate a scene, then render one sky image (PNG) of its clouds.
    #[command(allow_negative_numbers = true)]
    Render(render::RenderArgs),
    /// GPU frame benchmarks: resolution, coverage, parcel count (cloud map
    /// against the per-parcel pseudo-spheroids), features, the physics' share of the
    /// frame, and render error against GPU time. Writes CSV, JSON and PNGs.
    #[command(allow_negative_numbers = true)]
    Bench(bench::BenchArgs),
    /// Statistics of the cloud field seen from above: cloud fraction and
    /// its profile by height, the area-perimeter fractal dimension, the
    /// cloud-size density and its power-law exponent (CSV, JSON, plots).
    #[command(allow_negative_numbers = true)]
    Stats(stats::StatsArgs),
    /// Write the density field the renderer marches (extinction per
    /// metre on a grid over a box) as a Mitsuba 3 grid volume (.vol) or an
    /// OpenVDB fog volume (.vdb), with the sun, camera, phase function and
    /// albedo in a JSON sidecar, for offline renderers.
    #[command(allow_negative_numbers = true)]
    Export(export::ExportArgs),
    /// Scene files.
    Scene {
        #[command(subcommand)]
        command: SceneCommand,
    },
}

#[derive(Subcommand)]
enum SceneCommand {
    /// Validate a scene (and its sounding); report errors with file, line and key.
    #[command(after_help = "Example:\n  cumulus scene check scenes/bomex.toml")]
    Check {
        /// Scene TOML file, or the name of a built-in shipped scene.
        file: PathBuf,
    },
}

fn main() {
    quiet_wayland_probe();
    default_sigpipe();
    install_interrupt_handler();
    if let Err(e) = run(Cli::parse()) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Simulate(a) => simulate::run(a),
        Command::Profile(a) => profile::run(a),
        Command::Convergence(a) => convergence::run(a),
        Command::Render(a) => render::run(a),
        Command::Bench(a) => bench::run(a),
        Command::Stats(a) => stats::run(a),
        Command::Export(a) => export::run(a),
        Command::Scene {
            command: SceneCommand::Check { file },
        } => {
            // As every other command reads it: a file, or a shipped
            // scene's built-in copy by its bare name, said so.
            let scene = load_scene(&file)?;
            let atm = scene.atmosphere(None)?;
            let band = scene.band(&atm);
            println!(
                "{}: ok ({}; {} parcels, dt {} s, cloud band {:.0}-{:.0} m)",
                file.display(),
                if scene.name.is_empty() {
                    "unnamed"
                } else {
                    &scene.name
                },
                scene.physics.parcels,
                scene.physics.dt_s,
                band.bottom_m,
                band.top_m
            );
            Ok(())
        }
    }
}

/// Progress of a long run: a bar on a terminal; elsewhere (a log, CI, a
/// pipe) a plain line on stderr at every tenth of the work, so a long run
/// shows it is alive.
pub struct Progress {
    bar: ProgressBar,
    /// Without a terminal: what, the total and the units done.
    plain: Option<(String, u64, std::cell::Cell<u64>)>,
}

impl Progress {
    /// One more unit of work (`n` units).
    pub fn inc(&self, n: u64) {
        self.bar.inc(n);
        if let Some((what, len, done)) = &self.plain {
            let before = done.get();
            let after = before + n;
            done.set(after);
            let tenth = |k: u64| k * 10 / (*len).max(1);
            if tenth(after) > tenth(before) {
                eprintln!("{what}: {} % ({after} of {len})", tenth(after).min(10) * 10);
            }
        }
    }

    /// Moves on to `share` (0 to 1) of the work, for a bar of 100 units
    /// fed with shares (never back).
    pub fn to_share(&self, share: f32) {
        let target = (share.clamp(0.0, 1.0) * 100.0).round() as u64;
        let now = self.bar.position();
        if target > now {
            self.inc(target - now);
        }
    }

    /// Clears the bar (the plain lines stay).
    pub fn finish_and_clear(&self) {
        self.bar.finish_and_clear();
    }
}

fn progress_bar(len: u64, what: &str) -> Progress {
    let terminal = std::io::stderr().is_terminal();
    let bar = ProgressBar::with_draw_target(
        Some(len),
        if terminal {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        },
    );
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_message(what.to_owned());
    Progress {
        bar,
        plain: (!terminal).then(|| (what.to_owned(), len, std::cell::Cell::new(0))),
    }
}

/// The longest run a flag may ask for, s (as `render.time_s`): 116 days.
const MAX_DURATION_S: f64 = 1e7;

fn finite_positive(name: &str, v: f64) -> Result<()> {
    if !(v.is_finite() && v > 0.0 && v <= MAX_DURATION_S) {
        bail!(
            "{name} is {}, expected a positive number of seconds, at most {MAX_DURATION_S:e}",
            cumulus::sim::check::number(v)
        );
    }
    Ok(())
}

/// The scene `path` names ([`Scene::load_or_builtin`]: a file, or a
/// shipped scene's built-in copy by its bare name, said so).
fn load_scene(path: &Path) -> Result<Scene> {
    let (scene, builtin) = Scene::load_or_builtin(path)?;
    if builtin {
        eprintln!(
            "scene: the built-in copy of scenes/{}.toml (pass --scene PATH for a file)",
            path.display()
        );
    }
    Ok(scene)
}

/// The GPU probe loads the Vulkan drivers' window-system code, whose
/// Wayland client prints "error: XDG_RUNTIME_DIR is invalid or not set"
/// when that variable is missing, on runs that then succeed. The command
/// line opens no window, so it gives the probe an absolute (empty) runtime
/// directory: the Wayland connection fails quietly and nothing else
/// changes. Runs first in `main`, before any thread exists.
fn quiet_wayland_probe() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        // SAFETY: single-threaded here (the first statement of main); no
        // other code reads or writes the environment concurrently.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
    }
}

/// Rust starts a program with SIGPIPE ignored, so printing into a pipe
/// whose reader is gone (`cumulus profile ... | head -1`) fails, and
/// `println!` panics on that. Back to the default, the run ends quietly,
/// as `cat` or `grep` would; an output file being written is a temporary
/// one until it is renamed into place (where `/proc` lists the processes,
/// Linux, the next run into its folder removes it).
fn default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: single-threaded here (main's first statements); setting a
    // signal's disposition to SIG_DFL has no other effect on this process.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// The folders this run writes into: on SIGINT or SIGTERM the run's own
/// temporary files there are removed before it exits. (SIGKILL cannot be
/// caught; the next run into the same folder removes what it left.)
static OUTPUT_DIRS: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

fn install_interrupt_handler() {
    let handler = || {
        if let Ok(dirs) = OUTPUT_DIRS.lock() {
            for d in dirs.iter() {
                cumulus::io::remove_temp_files(d, Some(std::process::id()));
            }
        }
        eprintln!("interrupted: no output written");
        std::process::exit(130);
    };
    if let Err(e) = ctrlc::set_handler(handler) {
        eprintln!(
            "warning: cannot catch interrupts ({e}); an interrupted run may leave a .NAME.PID.tmp file"
        );
    }
}

/// Registers the folder `dir` that this run writes into (see
/// [`OUTPUT_DIRS`]) and removes the temporary files that runs which are gone
/// left there.
fn guard_output_dir(dir: &Path) {
    for f in cumulus::io::remove_temp_files(dir, None) {
        eprintln!("removed {} (left by an interrupted run)", f.display());
    }
    if let Ok(mut dirs) = OUTPUT_DIRS.lock() {
        dirs.push(dir.to_owned());
    }
}

/// Makes the output folder `dir` (and its parents), an existing file
/// there refused by name (the OS says only "File exists"), and guards it
/// ([`guard_output_dir`]).
fn create_output_folder(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!(
            "{}: is a file, expected a folder to write the outputs in",
            dir.display()
        );
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("{}: cannot create the folder", dir.display()))?;
    guard_output_dir(dir);
    Ok(())
}

/// [`guard_output_dir`] for the folder the output file `path` is written
/// in: the folder of the file its symbolic links lead to (where the
/// temporary file goes), none for a FIFO or a device (written as a
/// stream, no temporary file).
fn guard_output_file(path: &Path) {
    let file = match cumulus::io::output_target(path) {
        Ok(cumulus::io::OutputTarget::File(p)) => p,
        Ok(cumulus::io::OutputTarget::Stream(_)) => return,
        Err(_) => path.to_owned(),
    };
    match file.parent() {
        Some(d) if !d.as_os_str().is_empty() => guard_output_dir(d),
        _ => guard_output_dir(Path::new(".")),
    }
}

/// Writes linear RGB radiance (`rgb`, row-major, `width x height`) as
/// OpenEXR, atomically (`render --out x.exr`, `export --sky`).
fn write_exr(out: &Path, width: u32, height: u32, rgb: Vec<f32>) -> Result<()> {
    let img = image::Rgb32FImage::from_raw(width, height, rgb).context("image buffer size")?;
    cumulus::io::write_exr_atomically(out, &img)
        .with_context(|| format!("{}: cannot write image", out.display()))
}

/// Refuses an output `out` that is one of the files the run reads: the
/// scene file, its sounding, a `--sounding` given on the command line
/// (`inputs`, those that exist). Without it the run's atomic write would
/// replace its own input.
fn refuse_overwriting_inputs(out: &Path, inputs: &[(&str, PathBuf)]) -> Result<()> {
    let Ok(target) = std::fs::canonicalize(out) else {
        // No file there yet: it is none of the inputs, which exist.
        return Ok(());
    };
    for (what, input) in inputs {
        if std::fs::canonicalize(input).is_ok_and(|i| i == target) {
            bail!(
                "{}: is the {what} this run reads ({}); choose another --out",
                out.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// The files a run of `scene` reads: the scene file (none for a built-in
/// scene), its sounding, and the `--sounding` override.
fn scene_inputs(scene: &Scene, sounding: Option<&Path>) -> Vec<(&'static str, PathBuf)> {
    let mut v = Vec::new();
    if let Some(p) = &scene.source {
        v.push(("scene", p.clone()));
    }
    if let Some(p) = scene.atmosphere.sounding_path(scene.source.as_deref()) {
        v.push(("scene's sounding", p));
    }
    if let Some(p) = sounding {
        v.push(("sounding", p.to_owned()));
    }
    v
}

/// Fails early, before any simulation, when `path` cannot be written: it is
/// a directory, or its folder does not exist.
fn check_output_file(path: &Path) -> Result<()> {
    if path.is_dir() {
        bail!(
            "{}: is a directory, expected a file to write",
            path.display()
        );
    }
    // Where the bytes land: through a symbolic link, its target's folder
    // must exist (found only after the simulation, before); a stream
    // needs no folder.
    let target = match cumulus::io::output_target(path) {
        Ok(cumulus::io::OutputTarget::Stream(_)) => return Ok(()),
        Ok(cumulus::io::OutputTarget::File(p)) => p,
        Err(e) => bail!("{}: cannot write: {e}", path.display()),
    };
    if target != path {
        let dir = target.parent().unwrap_or(Path::new("."));
        if !dir.as_os_str().is_empty() && !dir.is_dir() {
            bail!(
                "{}: cannot write: it links to {}, whose folder {} does not exist",
                path.display(),
                target.display(),
                dir.display()
            );
        }
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        bail!(
            "{}: cannot write: the folder {} does not exist",
            path.display(),
            dir.display()
        );
    }
    Ok(())
}

/// The scene with the flags that override its keys applied, validated
/// again. `flags` pairs each flag with the key it sets: a bad value is
/// blamed on the flag that gave it, not on a line of the scene file.
fn with_overrides(
    mut scene: Scene,
    flags: &[(&str, &str)],
    apply: impl FnOnce(&mut Scene),
) -> Result<Scene> {
    apply(&mut scene);
    match scene.validate() {
        Ok(()) => Ok(scene),
        Err(cumulus::scene::SceneError::Invalid { key, message, .. })
            if flags.iter().any(|(_, k)| *k == key) =>
        {
            let flag = flags.iter().find(|(_, k)| *k == key).map_or("", |f| f.0);
            bail!("{flag} {message} (it sets {key})")
        }
        Err(e) => {
            let names: Vec<&str> = flags.iter().map(|f| f.0).collect();
            Err(e).with_context(|| format!("after applying {}", names.join("/")))
        }
    }
}

/// The GPU, from `WGPU_BACKEND` when set (the binary's edge reads the
/// environment, the library does not).
fn gpu_context() -> Result<cumulus::render::gpu::GpuContext, cumulus::render::gpu::GpuError> {
    let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all());
    cumulus::render::gpu::GpuContext::new(backends)
}
