//! Downlevel adapters (wgpu's OpenGL backend, Mesa's GL driver here): the
//! renderer refuses them with an error that names what they lack, and
//! nothing panics. Needs a GL adapter (Mesa's EGL); without one each test
//! prints `SKIPPED: no GL adapter` and passes, unless
//! `CUMULUS_REQUIRE_GL=1` (set by `.ci/run`, which installs Mesa's GL).

use std::path::PathBuf;
use std::process::Command;

use cumulus::render::cloud_map::{CloudMap, CloudMapConfig};
use cumulus::render::gpu::requirements::check_adapter;
use cumulus::render::gpu::{CloudRenderer, GpuContext, GpuError, RenderError};
use cumulus::scene::Scene;

fn gl_adapter() -> Option<wgpu::Adapter> {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::GL;
    let instance = wgpu::Instance::new(desc);
    let found = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::GL))
        .into_iter()
        .next();
    if found.is_none() {
        assert!(
            std::env::var("CUMULUS_REQUIRE_GL").ok().as_deref() != Some("1"),
            "CUMULUS_REQUIRE_GL=1 but no GL adapter was found"
        );
        eprintln!("SKIPPED: no GL adapter");
    }
    found
}

/// The adapter is refused up front, naming the render target format it
/// lacks; `GpuContext` refuses it the same way; and a device an
/// application made on it anyway gets an `Err` from `CloudRenderer::new`,
/// not a panic in a later frame.
#[test]
fn a_gl_adapter_is_refused_by_name() {
    let Some(adapter) = gl_adapter() else { return };
    eprintln!("adapter: {:?}", adapter.get_info());
    let refused = check_adapter(&adapter).expect_err("the GL adapter cannot draw the clouds");
    let text = refused.to_string();
    eprintln!("{text}");
    assert!(
        text.contains("R32Float") && text.contains("RENDER_ATTACHMENT"),
        "{text}"
    );
    match GpuContext::from_adapter(&adapter) {
        Err(GpuError::Unsupported(e)) => assert_eq!(e, refused),
        Err(e) => panic!("another error: {e}"),
        Ok(_) => panic!("a context on an adapter that cannot draw"),
    }
    // GpuContext::new over the GL backend alone finds it and refuses it.
    match GpuContext::new(wgpu::Backends::GL) {
        Err(GpuError::Unsupported(_)) => {}
        Err(e) => panic!("another error: {e}"),
        Ok(c) => panic!("{} accepted", c.describe()),
    }
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("an application's device"),
        required_limits:
            wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.limits()),
        ..Default::default()
    }))
    .expect("a GL device");
    let scene = Scene::builtin("fair_weather.toml")
        .expect("shipped")
        .expect("parses");
    let atm = scene.atmosphere(None).expect("atmosphere");
    let settings = scene
        .render
        .gpu_settings(scene.band(&atm), scene.physics.domain_size_m);
    let map = CloudMap::generate(&CloudMapConfig {
        size: 64,
        ..Default::default()
    });
    match CloudRenderer::new(
        &device,
        &queue,
        wgpu::TextureFormat::Rgba8UnormSrgb,
        &settings,
        &map,
        None,
    ) {
        Err(RenderError::Unsupported(e)) => {
            let text = e.to_string();
            assert!(text.contains("R32Float"), "{text}");
        }
        Err(e) => panic!("another error: {e}"),
        Ok(_) => panic!("a renderer on a device that cannot draw"),
    }
}

fn cumulus() -> Command {
    Command::new(env!("CARGO_BIN_EXE_cumulus"))
}

/// The embedding example, which `cargo test` builds with the others.
fn embed() -> PathBuf {
    let exe = std::env::current_exe().expect("test path");
    let dir = exe.parent().and_then(|d| d.parent()).expect("target dir");
    dir.join("examples")
        .join(format!("embed{}", std::env::consts::EXE_SUFFIX))
}

/// With GL the only backend (`WGPU_BACKEND=gl`): `--backend gpu` fails
/// with the missing format named, `--backend auto` draws on the CPU and
/// says why, and the embedding example exits with the same error; none
/// of them panics.
#[test]
fn start_up_on_gl_alone_says_why_not() {
    if gl_adapter().is_none() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let render = |backend: &str| {
        let o = cumulus()
            .args(["render", "--scene", "fair_weather", "--backend", backend])
            .args(["--width", "16", "--height", "12", "--light-photons", "4"])
            .args(["--time-s", "60", "--out"])
            .arg(dir.path().join(format!("{backend}.png")))
            .env("WGPU_BACKEND", "gl")
            .output()
            .expect("cumulus runs");
        (
            o.status.code(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (code, err) = render("gpu");
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("cannot draw the clouds") && err.contains("R32Float"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    let (code, err) = render("auto");
    assert_eq!(code, Some(0), "{err}");
    assert!(
        err.contains("backend: cpu") && err.contains("cannot draw the clouds"),
        "{err}"
    );
    assert!(dir.path().join("auto.png").is_file());
    let o = Command::new(embed())
        .arg(dir.path().join("embed.png"))
        .env("WGPU_BACKEND", "gl")
        .output()
        .expect("the embed example runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("cannot draw the clouds") && !err.contains("panicked"),
        "{err}"
    );
}
