//! The cantilever test (Peirce 1930; ASTM D1388) as an instrument: a strip of fabric
//! 2.5 cm wide lies on a ledge (a box collider) and is pushed over its edge at a slow,
//! steady speed until its tip has fallen 41.5° below the edge. The overhang `l` then
//! gives the bending length by Peirce's relation `c = l (cos(θ/2) / (8 tan θ))^(1/3)`
//! (≈ l/2 at θ = 41.5°), to be compared with the fabric's `(B / (ρ_A g))^(1/3)`.
//!
//! Peirce's relation is itself an approximation of the heavy inextensible elastica; the
//! instrument also solves the elastica ([`elastica_overhang`]) for the overhang at which
//! a strip clamped level at the edge has its tip at 41.5°.
//!
//! The strip lies between the ledge and a lid over it up to the edge (the standard's
//! weighted template, which keeps the strip flat up to the edge: a free strip would lift
//! off behind the edge, and its overhang would bend from further back; that measured
//! 27% short for denim).
//!
//! The strip starts flat on the ledge with 60% of the elastica's overhang past the edge,
//! settles for 1 s, and is then pushed by its back row (pinned, moved by the cloth's
//! frame) at 2 mm/s. Air drag is a rate of 5/s (`c = 5 m` a particle): the strip follows
//! the push quasi-statically (its lowest bending mode is about 2 Hz).

use bevy::math::{Affine3A, Mat3, Quat, Vec3};
use serde::Serialize;

use bevy_cloth::fabric::Fabric;
use bevy_cloth::layout::shape::{ClothPins, ClothShape};
use bevy_cloth::params::{ClothParams, Environment, Model, Substeps, XpbdParams};
use bevy_cloth::solver::{Collider, ColliderShape, Motion};

/// The strip's width, m (ASTM D1388).
pub const WIDTH: f32 = 0.025;
/// The tip angle the test stops at, degrees.
pub const TIP_ANGLE: f64 = 41.5;
/// The push speed, m/s.
pub const PUSH_SPEED: f32 = 0.002;
/// One step, s.
const STEP: f32 = 1.0 / 60.0;
/// Gravity, m/s².
pub const G: f32 = 9.81;

/// The model a strip is simulated with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum StripModel {
    /// XPBD, at its automatic substeps (with a fabric they keep its hinges' softening
    /// within 5%, a bending length within 1.6%).
    Xpbd,
    /// Mass-spring, at its automatic (stable) substeps.
    MassSpring,
}

/// One cantilever measurement: the bending length read two ways.
#[derive(Clone, Debug, Serialize)]
pub struct Cantilever {
    /// The preset's name (or `custom`).
    pub fabric: String,
    /// The model.
    pub model: StripModel,
    /// The grid spacing, m.
    pub spacing: f32,
    /// Substeps a step (of the ledge test's strip).
    pub substeps: u32,
    /// `(B / (ρ_A g))^(1/3)`, m.
    pub expected: f64,
    /// The elastica's overhang at 41.5° for this fabric, m.
    pub elastica_overhang: f64,
    /// The clamped strip's overhang at 41.5° (see [`clamped`]), m.
    pub overhang: f64,
    /// The bending length from it by Peirce's relation, m.
    pub measured: f64,
    /// `measured / expected − 1`.
    pub error: f64,
    /// The ledge test's overhang past the edge at 41.5° (see [`ledge`]), m.
    pub ledge_overhang: f64,
    /// The bending length from it by Peirce's relation, m.
    pub ledge_measured: f64,
    /// `ledge_measured / expected − 1`.
    pub ledge_error: f64,
}

/// Peirce's bending length for overhang `l` at tip angle `theta` (degrees).
pub fn peirce(l: f64, theta: f64) -> f64 {
    let t = theta.to_radians();
    l * ((0.5 * t).cos() / (8.0 * t.tan())).cbrt()
}

/// The heavy inextensible elastica clamped level: the overhang (in bending lengths
/// `c`) at which the chord from the clamp to the tip falls `theta` degrees. With
/// `s` along the strip over its length `l` and `λ = l³/c³`, the angle `φ(s)` below level
/// obeys `φ'' = −λ (1 − s) cos φ`, `φ(0) = 0`, `φ'(1) = 0`; shot on `φ'(0)` (RK4, 2,000
/// steps), then bisected on `λ`.
pub fn elastica_overhang(theta: f64) -> f64 {
    // The instruments ask for 41.5° several times a measurement: solved once.
    static AT_TIP_ANGLE: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
    if theta == TIP_ANGLE {
        return *AT_TIP_ANGLE.get_or_init(|| solve_elastica_overhang(theta));
    }
    solve_elastica_overhang(theta)
}

/// [`elastica_overhang`], solved.
fn solve_elastica_overhang(theta: f64) -> f64 {
    let target = theta.to_radians();
    let chord = |lambda: f64| {
        // Shooting: the start slope that leaves no moment at the tip.
        let tip = |slope: f64| integrate(lambda, slope);
        let (mut lo, mut hi) = (0.0, lambda);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if tip(mid).0 > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let (_, x, y) = tip(0.5 * (lo + hi));
        (-y).atan2(x)
    };
    let (mut lo, mut hi) = (0.1, 100.0);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if chord(mid) > target {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    (0.5 * (lo + hi)).cbrt()
}

/// Integrates the elastica from the clamp with start slope `slope`: the slope left at
/// the tip (0 for the true shape: the tip carries no moment) and the tip's position
/// (x along, y up, in strip lengths). `φ` grows downward; `φ'` falls along the strip.
fn integrate(lambda: f64, slope: f64) -> (f64, f64, f64) {
    let n = 2000;
    let h = 1.0 / n as f64;
    // State: φ, φ', x, y.
    let f = |s: f64, u: [f64; 4]| -> [f64; 4] {
        [
            u[1],
            -lambda * (1.0 - s) * u[0].cos(),
            u[0].cos(),
            -u[0].sin(),
        ]
    };
    let mut u = [0.0, slope, 0.0, 0.0];
    for k in 0..n {
        let s = k as f64 * h;
        let add = |u: [f64; 4], d: [f64; 4], t: f64| std::array::from_fn(|i| u[i] + t * d[i]);
        let k1 = f(s, u);
        let k2 = f(s + 0.5 * h, add(u, k1, 0.5 * h));
        let k3 = f(s + 0.5 * h, add(u, k2, 0.5 * h));
        let k4 = f(s + h, add(u, k3, h));
        u = std::array::from_fn(|i| u[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    (u[1], u[2], u[3])
}

/// Measures `fabric`'s bending length with `model` at grid `spacing` (m), both ways.
pub fn measure(
    name: &str,
    fabric: Fabric,
    model: StripModel,
    spacing: f32,
) -> Result<Cantilever, String> {
    let expected = f64::from(fabric.bending_length(G));
    let elastica_overhang = elastica_overhang(TIP_ANGLE) * expected;
    let overhang = clamped(fabric, model, spacing)?;
    let (ledge_overhang, substeps) = ledge(name, fabric, model, spacing)?;
    let (measured, ledge_measured) = (
        peirce(overhang, TIP_ANGLE),
        peirce(ledge_overhang, TIP_ANGLE),
    );
    Ok(Cantilever {
        fabric: name.to_string(),
        model,
        spacing,
        substeps,
        expected,
        elastica_overhang,
        overhang,
        measured,
        error: measured / expected - 1.0,
        ledge_overhang,
        ledge_measured,
        ledge_error: ledge_measured / expected - 1.0,
    })
}

/// The parameters of a strip of `fabric` at `spacing` with `model` (no strain limit, a
/// little air drag: a rate of `rate` a second).
fn strip_params(fabric: Fabric, model: StripModel, spacing: f32, rate: f32) -> ClothParams {
    ClothParams {
        model: match model {
            StripModel::Xpbd => Model::Xpbd(XpbdParams {
                tethers: false,
                ..XpbdParams::default()
            }),
            StripModel::MassSpring => Model::MassSpring,
        },
        fabric: Some(fabric),
        substeps: Substeps::Auto { max: 8192 },
        strain_limit: None,
        drag: rate * fabric.areal_density * spacing * spacing,
        ..ClothParams::seeds()
    }
}

/// The grid's rows (local −y) along +x, its columns (local x) along −z, its normal up.
fn level() -> Quat {
    Quat::from_mat3(&Mat3::from_cols(Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y))
}

/// Gravity along −y, no wind.
fn still_air() -> Environment {
    let mut env = Environment::default();
    env.wind.strength = 0.0;
    env.gravity = Vec3::new(0.0, -G, 0.0);
    env
}

/// The chord angle below level from `from` to the mean of the last row of a strip
/// `across` particles wide, degrees.
fn tip_angle(x: &[Vec3], across: u32, from: Vec3) -> f64 {
    let n = x.len() as u32;
    let tip = (n - across..n).map(|i| x[i as usize]).sum::<Vec3>() / across as f32 - from;
    f64::from(-tip.y).atan2(f64::from(tip.x)).to_degrees()
}

/// The clamped reading: the overhang at which a strip clamped level has its tip at
/// 41.5°, found by the secant method on the overhang, each guess a strip at rest
/// (4 s at a drag rate of 20/s).
///
/// The strip's first two rows are pinned. The last pinned row's hinge stands for half a
/// cell on each side of it, so the discrete strip bends as a continuous one clamped half
/// a cell behind that row: that is where the clamp is. A strip of `n + ½` cells past it (`n` free rows) is
/// the exact discrete clamped cantilever, and matches the elastica of that length
/// within 0.3% (the test `a_clamped_strip_is_the_elastica`). The overhang is made
/// continuous by stretching the spacing a little: `n` is fixed by the nominal
/// spacing at the elastica's overhang, and each guess `l` lays the strip at `l/(n + ½)`.
pub fn clamped(fabric: Fabric, model: StripModel, spacing: f32) -> Result<f64, String> {
    let guess = elastica_overhang(TIP_ANGLE) * f64::from(fabric.bending_length(G));
    let rows = ((guess / f64::from(spacing)) - 0.5).round().max(2.0) as u32;
    let angle = |l: f64| -> Result<f64, String> {
        let s = (l / (f64::from(rows) + 0.5)) as f32;
        clamped_tip(fabric, model, s, rows).map(|(a, _)| a - TIP_ANGLE)
    };
    let (mut a, mut b) = (guess, 0.9 * guess);
    let (mut fa, mut fb) = (angle(a)?, angle(b)?);
    for _ in 0..12 {
        // 0.02° is 0.03% of the overhang here (about 2° a millimetre).
        if fb.abs() < 0.02 || fa == fb {
            break;
        }
        let c = b - fb * (b - a) / (fb - fa);
        (a, fa) = (b, fb);
        b = c.clamp(0.5 * guess, 2.0 * guess);
        fb = angle(b)?;
    }
    // The strip at rest is a little noisy (a settle of 4 s): 0.25° is 0.3% of the overhang.
    if fb.abs() > 0.25 {
        return Err(format!(
            "the clamped strip did not settle on 41.5° ({fb:+.2}° off)"
        ));
    }
    Ok(b)
}

/// A strip 2.5 cm wide at `spacing` with two pinned rows and `free` rows past them, the
/// clamp (half a cell behind the last pinned row) at the origin, at rest: its tip's
/// chord angle (degrees) and position.
pub fn clamped_tip(
    fabric: Fabric,
    model: StripModel,
    spacing: f32,
    free: u32,
) -> Result<(f64, Vec3), String> {
    let across = (WIDTH / spacing).round() as u32 + 1;
    let along = free + 2;
    let params = strip_params(fabric, model, spacing, 20.0);
    let frame = Affine3A::from_rotation_translation(level(), Vec3::new(-0.5 * spacing, 0.0, 0.0));
    let shape = ClothShape::Grid {
        width: across,
        height: along,
        spacing,
    };
    let pins = ClothPins::Indices((0..2 * across).collect());
    let mut cloth = shape
        .build_solver(&pins, &params, frame)
        .map_err(|e| e.to_string())?;
    let env = still_air();
    for _ in 0..240 {
        cloth.step(STEP, &env);
    }
    if !cloth.is_stable() {
        return Err("the clamped strip went unstable".into());
    }
    let x = cloth.positions();
    let n = x.len() as u32;
    let tip = (n - across..n).map(|i| x[i as usize]).sum::<Vec3>() / across as f32;
    Ok((tip_angle(x, across, Vec3::ZERO), tip))
}

/// The ledge reading, the test as the standard runs it: the overhang past the ledge's
/// edge when the tip reaches 41.5°, and the substeps a step.
///
/// A discrete strip under a sharp-edged lid is held up to its last row behind the edge,
/// so it bends as if clamped half a cell behind that row: between half a cell and one
/// and a half cells behind the edge as the rows pass it. Its overhang is therefore too long
/// by about a cell on average, and the reading short by an amount that halves with the
/// spacing (`docs/fabric.md`).
pub fn ledge(
    name: &str,
    fabric: Fabric,
    model: StripModel,
    spacing: f32,
) -> Result<(f64, u32), String> {
    let elastica = elastica_overhang(TIP_ANGLE) * f64::from(fabric.bending_length(G));
    let across = (WIDTH / spacing).round() as u32 + 1;
    // Long enough for the overhang and a quarter of it behind the edge.
    let along = ((1.6 * elastica) as f32 / spacing).ceil() as u32 + 1;
    let length = (along - 1) as f32 * spacing;
    let params = strip_params(fabric, model, spacing, 5.0);
    let thickness = 0.25 * spacing;
    let start = (0.6 * elastica) as f32;
    let place = |overhang: f32| {
        Affine3A::from_rotation_translation(level(), Vec3::new(overhang - length, thickness, 0.0))
    };
    let shape = ClothShape::Grid {
        width: across,
        height: along,
        spacing,
    };
    let pins = ClothPins::Indices((0..across).collect());
    let mut cloth = shape
        .build_solver(&pins, &params, place(start))
        .map_err(|e| e.to_string())?;
    // The ledge, and the standard's weighted template over the strip up to the edge: a
    // lid `2·thickness` above the ledge, so the strip behind the edge lies flat between
    // them (without it, it lifts off behind the edge and the overhang is no clamp).
    let block = |y: f32| Collider {
        shape: ColliderShape::from(bevy_cloth::solver::shapes::Cuboid::new(
            Vec3::new(-0.5, y, 0.0),
            Quat::IDENTITY,
            Vec3::splat(0.5),
        )),
        thickness,
        friction: 0.1,
        motion: Motion::NONE,
    };
    cloth.set_colliders([block(-0.5), block(2.0 * thickness + 0.5)]);
    let env = still_air();
    let edge = Vec3::new(0.0, thickness, 0.0);
    for _ in 0..60 {
        cloth.step(STEP, &env);
    }
    let settled = tip_angle(cloth.positions(), across, edge);
    if settled >= TIP_ANGLE {
        return Err(format!(
            "{name}: the tip is already {settled:.1}° down at 60% of the elastica's overhang"
        ));
    }
    let (mut overhang, mut before) = (start, settled);
    while overhang < 1.3 * elastica as f32 {
        let next = overhang + PUSH_SPEED * STEP;
        cloth.set_frame(place(next));
        cloth.step(STEP, &env);
        if !cloth.is_stable() {
            return Err(format!("{name}: the strip went unstable at {next:.4} m"));
        }
        let now = tip_angle(cloth.positions(), across, edge);
        if now >= TIP_ANGLE {
            let t = (TIP_ANGLE - before) / (now - before);
            let l = f64::from(overhang) + t * f64::from(next - overhang);
            return Ok((l, cloth.substeps()));
        }
        (overhang, before) = (next, now);
    }
    Err(format!("{name}: the tip never reached {TIP_ANGLE}°"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn peirce_and_the_elastica_agree_on_the_overhang() {
        // Peirce's relation is a fit to the elastica within about 1%.
        let l = elastica_overhang(TIP_ANGLE);
        let c = peirce(l, TIP_ANGLE);
        assert!(
            (c - 1.0).abs() < 0.02,
            "elastica overhang {l:.4} c gives c = {c:.4}"
        );
    }

    /// The heavy elastica of length `l` clamped level: its tip (x along, y up), m.
    fn elastica_tip(l: f64, c: f64) -> (f64, f64) {
        let lambda = (l / c).powi(3);
        let (mut lo, mut hi) = (0.0, lambda);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if integrate(lambda, mid).0 > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        let (_, x, y) = integrate(lambda, 0.5 * (lo + hi));
        (x * l, y * l)
    }

    #[test]
    fn a_clamped_strip_is_the_elastica() {
        // Denim, 2.5 mm, 11 free rows: 28.75 mm past the clamp, which is half a cell
        // behind the last pinned row (`clamped`). Mass-spring rests where its forces
        // balance; the tip is where the elastica's is within 0.3% of the length.
        let (s, rows) = (0.0025, 11);
        let (_, tip) = clamped_tip(Fabric::DENIM, StripModel::MassSpring, s, rows).unwrap();
        let l = (f64::from(rows) + 0.5) * f64::from(s);
        let (x, y) = elastica_tip(l, f64::from(Fabric::DENIM.bending_length(G)));
        let off = ((f64::from(tip.x) - x).powi(2) + (f64::from(tip.y) - y).powi(2)).sqrt();
        assert!(
            off < 0.003 * l,
            "tip ({:.2}, {:.2}) mm, elastica ({:.2}, {:.2}) mm",
            tip.x * 1e3,
            tip.y * 1e3,
            x * 1e3,
            y * 1e3
        );
    }

    #[test]
    fn both_models_measure_the_fabrics_bending_length() {
        // Ponte at the default 2.5 mm: the clamped reading within 5% of
        // (B/(ρ_A g))^(1/3) for XPBD and mass-spring, the two within 1% of each other.
        let xpbd = clamped(Fabric::PONTE, StripModel::Xpbd, 0.0025).unwrap();
        let ms = clamped(Fabric::PONTE, StripModel::MassSpring, 0.0025).unwrap();
        let expected = f64::from(Fabric::PONTE.bending_length(G));
        for l in [xpbd, ms] {
            let c = peirce(l, TIP_ANGLE);
            assert!(
                (c / expected - 1.0).abs() < 0.05,
                "c {c:.5} m, expected {expected:.5}"
            );
        }
        assert!(
            (xpbd / ms - 1.0).abs() < 0.01,
            "XPBD {xpbd:.5}, mass-spring {ms:.5} m"
        );
    }
}
