//! The render test: the curtain example under Xvfb with Mesa's software Vulkan, two
//! screenshots, and checks from the pixels that the cloth is drawn where the camera looks
//! and that it moved between them. Catches a black window, a mesh that is not updated and
//! a frozen simulation.
//!
//! Needs `Xvfb` and a Vulkan driver (`apt-get install xvfb mesa-vulkan-drivers`; `.ci/run`
//! installs them). Without Xvfb the test says so and passes, except under CI (`CI` set),
//! where it fails.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use image::RgbImage;

/// `target/debug/examples/curtain`, built by `cargo test` beside this test binary.
fn example_binary(name: &str) -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let profile_dir = exe.parent().and_then(Path::parent).unwrap();
    profile_dir.join("examples").join(name)
}

struct Xvfb(Child);

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A private X display, or `None` when Xvfb is not installed.
fn start_xvfb(display: &str) -> Option<Xvfb> {
    let child = Command::new("Xvfb")
        .args([display, "-screen", "0", "1280x720x24", "-nolisten", "tcp"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    let xvfb = Xvfb(child);
    let socket = format!("/tmp/.X11-unix/X{}", display.trim_start_matches(':'));
    let start = Instant::now();
    while !Path::new(&socket).exists() {
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "Xvfb did not start on {display}"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    Some(xvfb)
}

/// Cloth-coloured pixels (the curtain is dark red) in the 3D view, right of the panel.
fn cloth_mask(image: &RgbImage) -> Vec<bool> {
    image
        .enumerate_pixels()
        .map(|(x, _, p)| {
            let [r, g, b] = p.0.map(f32::from);
            x > 320 && r > 80.0 && r > 1.5 * g && r > 1.5 * b
        })
        .collect()
}

#[test]
fn curtain_renders_and_moves() {
    let display = ":97";
    let _xvfb = match start_xvfb(display) {
        Some(x) => x,
        None if std::env::var_os("CI").is_some() => {
            panic!("Xvfb is missing: install xvfb mesa-vulkan-drivers")
        }
        None => {
            eprintln!(
                "render test skipped: Xvfb is not installed (apt-get install xvfb mesa-vulkan-drivers)"
            );
            return;
        }
    };
    let out = std::env::temp_dir().join(format!("bevy_cloth_render_{}", std::process::id()));
    std::fs::create_dir_all(&out).unwrap();
    let (early, late) = (out.join("early.png"), out.join("late.png"));
    let binary = example_binary("curtain");
    assert!(binary.exists(), "{} was not built", binary.display());
    let output = Command::new(&binary)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .args(["--set", "environment.wind.strength=0.003"])
        .args(["--screenshot", early.to_str().unwrap(), "--frames", "30"])
        .args(["--screenshot", late.to_str().unwrap(), "--frames", "90"])
        .output()
        .expect("the curtain example runs");
    let log = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success(),
        "curtain exited with {}:\n{log}",
        output.status
    );

    let a = image::open(&early).expect("first screenshot").to_rgb8();
    let b = image::open(&late).expect("second screenshot").to_rgb8();
    assert_eq!(a.dimensions(), (1280, 720));
    let (ma, mb) = (cloth_mask(&a), cloth_mask(&b));
    let total = ma.len() as f32;
    for (name, mask) in [("early", &ma), ("late", &mb)] {
        let count = mask.iter().filter(|m| **m).count();
        let fraction = count as f32 / total;
        assert!(
            (0.05..0.6).contains(&fraction),
            "{name}: cloth covers {:.1}% of the window",
            fraction * 100.0
        );
        // Its centre is in the middle of the 3D view, where the camera looks.
        let (sx, sy) = mask
            .iter()
            .enumerate()
            .filter(|(_, m)| **m)
            .fold((0.0, 0.0), |(sx, sy), (i, _)| {
                (sx + (i % 1280) as f32, sy + (i / 1280) as f32)
            });
        let (cx, cy) = (sx / count as f32, sy / count as f32);
        assert!(
            (500.0..1100.0).contains(&cx) && (150.0..600.0).contains(&cy),
            "{name}: cloth centred at ({cx}, {cy})"
        );
    }
    let changed = ma.iter().zip(&mb).filter(|(x, y)| x != y).count() as f32 / total;
    assert!(
        changed > 0.003,
        "the cloth did not move: {:.2}% of pixels changed",
        changed * 100.0
    );
    let _ = std::fs::remove_dir_all(&out);
}
