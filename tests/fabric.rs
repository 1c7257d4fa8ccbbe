//! Fabric in physical units: presets by name, masses from area, the same fabric at two
//! resolutions, and the models and layouts that refuse it.

use bevy::math::{Affine3A, Vec3};
use bevy_cloth::error::ClothError;
use bevy_cloth::fabric::Fabric;
use bevy_cloth::layout::shape::{ClothPins, ClothShape};
use bevy_cloth::params::{ClothParams, Environment, Model, ShapeMatchingParams};
use bevy_cloth::solver::{ClothSolver, Layout};

#[test]
fn a_preset_is_named_in_a_scene_file_and_an_unknown_one_is_refused() {
    let params: ClothParams = ron::from_str(r#"(fabric: Some("denim"))"#).unwrap();
    assert_eq!(params.fabric, Some(Fabric::DENIM));
    let e = ron::from_str::<ClothParams>(r#"(fabric: Some("velvet"))"#).unwrap_err();
    assert!(e.to_string().contains("unknown fabric"), "{e}");
    let numbers: ClothParams = ron::from_str(
        "(fabric: Some((areal_density: 0.2, stretch: 500.0, shear: 20.0, bending: 1e-5)))",
    )
    .unwrap();
    assert_eq!(numbers.fabric.unwrap().bending, 1e-5);
    for (name, fabric) in Fabric::PRESETS {
        fabric.validate().unwrap();
        assert_eq!(Fabric::named(name).unwrap(), fabric);
        assert_eq!(fabric.name(), Some(name));
    }
}

/// A `side`-particle square curtain of 1 m of `fabric` hung from its top row with `model`
/// at its automatic substeps, stepped 3 s with a little drag (a rate of 2/s).
fn hung(fabric: Fabric, side: u32, model: Model) -> ClothSolver {
    let spacing = 1.0 / (side - 1) as f32;
    let params = ClothParams {
        model,
        fabric: Some(fabric),
        drag: 2.0 * fabric.areal_density * spacing * spacing,
        strain_limit: None,
        ..ClothParams::default()
    };
    let shape = ClothShape::Grid {
        width: side,
        height: side,
        spacing,
    };
    let mut cloth = shape
        .build_solver(&ClothPins::TopRow, &params, Affine3A::IDENTITY)
        .unwrap();
    let mut env = Environment::default();
    env.wind.strength = 0.0;
    for _ in 0..188 {
        cloth.step(0.016, &env);
    }
    cloth
}

/// How far the bottom row's mean has dropped below where it hung at rest, m.
fn sag(cloth: &ClothSolver, side: u32) -> f32 {
    let x = cloth.positions();
    let bottom = ((side - 1) * side..side * side)
        .map(|i| x[i as usize].y)
        .sum::<f32>()
        / side as f32;
    -1.0 - bottom
}

#[test]
fn the_same_fabric_at_twice_the_resolution_weighs_and_sags_the_same() {
    // Mass-spring: its rest under load is the forces' balance at any step. XPBD's (one
    // iteration a substep, multipliers from 0) is softer by `h² Σ w |∇C|² / α`, which
    // grows as the particles get lighter: 25 against 34 mm of sag here.
    let model = Model::MassSpring;
    let (coarse, fine) = (
        hung(Fabric::INTERLOCK, 21, model),
        hung(Fabric::INTERLOCK, 41, model),
    );
    for cloth in [&coarse, &fine] {
        let mass: f32 = cloth.particles().mass.iter().sum();
        assert!(
            (mass - 0.187).abs() < 1e-4,
            "1 m² of interlock weighs {mass} kg"
        );
        assert!(cloth.is_stable());
    }
    let (a, b) = (sag(&coarse, 21), sag(&fine, 41));
    eprintln!("sag at 5 cm {a:.5} m, at 2.5 cm {b:.5} m");
    assert!(a > 0.0 && b > 0.0, "sags {a} and {b} m");
    assert!(
        (a - b).abs() <= 0.05 * a.max(b),
        "sags {a:.5} (5 cm) and {b:.5} m (2.5 cm)"
    );
}

#[test]
fn models_without_springs_and_clothes_without_triangles_refuse_a_fabric() {
    let params = ClothParams {
        model: Model::ShapeMatching(ShapeMatchingParams::default()),
        fabric: Some(Fabric::DENIM),
        ..ClothParams::default()
    };
    assert!(matches!(
        params.validate(),
        Err(ClothError::ModelLacks { .. })
    ));
    let rope = Layout::from_springs(&[Vec3::ZERO, Vec3::X], &[[0, 1]]).unwrap();
    let params = ClothParams {
        fabric: Some(Fabric::DENIM),
        ..ClothParams::default()
    };
    let e = ClothSolver::new(rope, &[], &params, Affine3A::IDENTITY).unwrap_err();
    assert!(matches!(e, ClothError::FabricNeedsSurface), "{e}");
}
