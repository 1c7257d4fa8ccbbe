//! What a cloth is made of and held by: its grid's springs, welded meshes, pins that
//! follow the frame, attached particles, tearing, parameters refused with their field.

use crate::common::*;
use bevy::math::{Affine3A, Vec3};
use bevy_cloth::params::{
    Environment, Integrator, Model, PatchParams, SpringFamily, SpringParams, Substeps, XpbdParams,
};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, Layout, SpringKind};

fn tear_test_cloth(model: Model, tear_ratio: f32, gravity: f32) -> (ClothSolver, Environment) {
    let params = ClothParams {
        model,
        tear_ratio: Some(tear_ratio),
        drag: 1e-3,
        ..conservative(Integrator::Verlet)
    };
    let cloth = ClothShape::Grid {
        width: 6,
        height: 6,
        spacing: 0.1,
    }
    .build_solver(&ClothPins::TopRow, &params, Affine3A::IDENTITY)
    .unwrap();
    let env = Environment {
        gravity: Vec3::new(0.0, -gravity, 0.0),
        ..no_wind()
    };
    (cloth, env)
}

#[test]
fn cloth_tears_past_its_ratio_and_not_below() {
    // Mass-spring, and XPBD's constraints (a torn one stops acting from the next step).
    for model in [Model::MassSpring, Model::Xpbd(XpbdParams::default())] {
        tears_past_its_ratio_and_not_below(model);
    }
}

fn tears_past_its_ratio_and_not_below(model: Model) {
    // Under normal gravity the top springs stretch by m g (rows below) / k ≈ 5%.
    let (mut calm, env) = tear_test_cloth(model, 1.5, 9.81);
    for _ in 0..300 {
        calm.step(DT, &env);
    }
    assert_eq!(calm.torn_count(), 0);
    assert!(calm.triangle_visible().iter().all(|v| *v));

    // Under 200 g the same springs would stretch by ~1000%: they tear, faces hide.
    let (mut pulled, env) = tear_test_cloth(model, 1.5, 200.0 * 9.81);
    let mut torn = Vec::new();
    for _ in 0..300 {
        let n = pulled.begin_step(DT);
        for _ in 0..n {
            pulled.substep(&env);
        }
        pulled.end_step();
        torn.extend_from_slice(pulled.last_torn());
    }
    assert!(!torn.is_empty());
    assert_eq!(torn.len(), pulled.torn_count());
    assert!(torn.iter().all(|&s| !pulled.springs().alive[s as usize]));
    assert!(
        pulled.triangle_visible().iter().any(|v| !*v),
        "no face was hidden"
    );
    assert!(pulled.is_finite(), "{}", model.kind());
    // A torn spring stops pulling: what hung below the tears fell freely (under 200 g for
    // the seconds left, kilometres; held by a spring that still acted, a few metres).
    let lowest = pulled
        .positions()
        .iter()
        .map(|p| p.y)
        .fold(f32::INFINITY, f32::min);
    assert!(
        lowest < -100.0,
        "{}: lowest particle at {lowest} m",
        model.kind()
    );
}

#[test]
fn pins_follow_the_frame() {
    let params = conservative(Integrator::Verlet);
    let mut cloth = swinging_cloth(&params);
    let env = no_wind();
    let before: Vec<Vec3> = cloth
        .pins()
        .iter()
        .map(|&i| cloth.positions()[i as usize])
        .collect();
    let shift = Vec3::new(0.3, 0.0, -0.2);
    cloth.set_frame(Affine3A::from_translation(shift) * cloth.frame());
    cloth.step(DT, &env);
    for (k, &i) in cloth.pins().iter().enumerate() {
        assert!((cloth.positions()[i as usize] - (before[k] + shift)).length() < 1e-5);
    }
    // The rest of the cloth is dragged along over the following steps.
    let centre =
        |c: &ClothSolver| c.positions().iter().copied().sum::<Vec3>() / c.particle_count() as f32;
    let c0 = centre(&cloth);
    for _ in 0..200 {
        cloth.step(DT, &env);
    }
    assert!(
        (centre(&cloth).x - c0.x).abs() < 0.5,
        "cloth did not stay with its pins"
    );
}

#[test]
fn grid_topology_matches_sladovics() {
    let cloth = ClothShape::Grid {
        width: 5,
        height: 4,
        spacing: 0.1,
    }
    .build_solver(
        &ClothPins::TopRow,
        &ClothParams {
            springs: SpringParams {
                bend_diagonal: SpringFamily::new(10.0),
                ..SpringParams::default()
            },
            ..ClothParams::seeds()
        },
        Affine3A::IDENTITY,
    )
    .unwrap();
    let s = cloth.springs();
    let count = |k: SpringKind| s.ranges[k as usize].len();
    let (w, h) = (5, 4);
    assert_eq!(count(SpringKind::Structural), (w - 1) * h + w * (h - 1));
    assert_eq!(count(SpringKind::Shear), 2 * (w - 1) * (h - 1));
    assert_eq!(count(SpringKind::Bend), (w - 2) * h + w * (h - 2));
    assert_eq!(count(SpringKind::BendDiagonal), 2 * (w - 2) * (h - 2));
    let rest = |k: SpringKind| s.rest_length[s.ranges[k as usize].start];
    assert!((rest(SpringKind::Structural) - 0.1).abs() < 1e-6);
    assert!((rest(SpringKind::Shear) - 0.1 * 2f32.sqrt()).abs() < 1e-6);
    assert!((rest(SpringKind::Bend) - 0.2).abs() < 1e-6);
    assert!((rest(SpringKind::BendDiagonal) - 0.2 * 2f32.sqrt()).abs() < 1e-6);
    assert_eq!(cloth.pins(), &[0, 1, 2, 3, 4]);
    assert_eq!(cloth.triangles().len(), 2 * (w - 1) * (h - 1));
    // Switching a family off removes it from the acting springs.
    let mut c = cloth.clone();
    let all = c.spring_count();
    let mut p = *c.params();
    p.springs.shear.enabled = false;
    c.set_params(&p).unwrap();
    assert_eq!(c.spring_count(), all - count(SpringKind::Shear));
}

#[test]
fn bad_parameters_return_their_error() {
    let grid = ClothShape::Grid {
        width: 4,
        height: 4,
        spacing: 0.1,
    };
    let ok = ClothParams::seeds();
    let build = |shape: &ClothShape, pins: &ClothPins, params: &ClothParams| {
        shape.build_solver(pins, params, Affine3A::IDENTITY).err()
    };
    let field = |e: Option<ClothError>| match e {
        Some(ClothError::InvalidParameter { field, .. }) => field,
        other => panic!("expected an invalid parameter, got {other:?}"),
    };
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams {
                node_mass: -1.0,
                ..ok
            }
        )),
        "node_mass"
    );
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams {
                node_mass: f32::NAN,
                ..ok
            }
        )),
        "node_mass"
    );
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams {
                node_mass: 0.0,
                ..ok
            }
        )),
        "node_mass"
    );
    let mut stiff = ok;
    stiff.springs.shear.stiffness = -5.0;
    assert_eq!(
        field(build(&grid, &ClothPins::None, &stiff)),
        "springs.shear.stiffness"
    );
    stiff.springs.shear.stiffness = f32::INFINITY;
    assert_eq!(
        field(build(&grid, &ClothPins::None, &stiff)),
        "springs.shear.stiffness"
    );
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams { drag: -0.1, ..ok }
        )),
        "drag"
    );
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams {
                tear_ratio: Some(0.9),
                ..ok
            }
        )),
        "tear_ratio"
    );
    assert_eq!(
        field(build(
            &grid,
            &ClothPins::None,
            &ClothParams {
                substeps: Substeps::Fixed(0),
                ..ok
            }
        )),
        "substeps"
    );
    for spacing in [0.0, -0.1, f32::NAN] {
        let shape = ClothShape::Grid {
            width: 4,
            height: 4,
            spacing,
        };
        assert_eq!(field(build(&shape, &ClothPins::None, &ok)), "shape.spacing");
    }
    let thin = ClothShape::Grid {
        width: 1,
        height: 5,
        spacing: 0.1,
    };
    assert_eq!(
        build(&thin, &ClothPins::None, &ok),
        Some(ClothError::GridTooSmall {
            width: 1,
            height: 5
        })
    );
    assert_eq!(
        build(&grid, &ClothPins::Indices(vec![3, 16]), &ok),
        Some(ClothError::PinOutOfRange {
            index: 16,
            count: 16
        })
    );
    // A running cloth refuses bad parameters and keeps its old ones.
    let mut cloth = grid
        .build_solver(&ClothPins::None, &ok, Affine3A::IDENTITY)
        .unwrap();
    assert!(
        cloth
            .set_params(&ClothParams {
                node_mass: -1.0,
                ..ok
            })
            .is_err()
    );
    assert_eq!(cloth.params(), &ok);
}

/// A `n × n`-vertex square mesh, 10 cm across, in the xy-plane: its positions and
/// triangles, indexed.
fn square_mesh(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let positions = (0..n * n)
        .map(|k| Vec3::new((k % n) as f32, -((k / n) as f32), 0.0) * (0.1 / (n - 1) as f32))
        .collect();
    let mut triangles = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let (a, b, c, d) = (
                j * n + i,
                j * n + i + 1,
                (j + 1) * n + i,
                (j + 1) * n + i + 1,
            );
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
    }
    (positions, triangles)
}

/// The mesh hung from its top row for 2 s: the lowest point.
fn hang_mesh(positions: &[Vec3], triangles: &[[u32; 3]]) -> (ClothSolver, f32) {
    let params = ClothParams {
        springs: SpringParams::from_structural(50.0),
        ..ClothParams::seeds()
    };
    let layout = Layout::from_mesh(positions, triangles).unwrap();
    let pins = ClothPins::TopRow.resolve_for(&layout).unwrap();
    let mut c = ClothSolver::new(layout, &pins, &params, Affine3A::IDENTITY).unwrap();
    for _ in 0..125 {
        c.step(DT, &no_wind());
    }
    assert!(c.is_stable());
    let lowest = c.positions().iter().map(|p| p.y).fold(f32::MAX, f32::min);
    (c, lowest)
}

#[test]
fn meshes_weld_coincident_vertices_into_one_cloth() {
    let (positions, triangles) = square_mesh(6);
    let (indexed, lowest) = hang_mesh(&positions, &triangles);
    assert_eq!(indexed.particle_count(), 36);
    // Non-indexed: every triangle has its own three vertices (as many exporters write).
    let loose: Vec<Vec3> = triangles
        .iter()
        .flat_map(|t| t.map(|v| positions[v as usize]))
        .collect();
    let loose_triangles: Vec<[u32; 3]> = (0..triangles.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let (welded, welded_lowest) = hang_mesh(&loose, &loose_triangles);
    assert_eq!(welded.particle_count(), 36, "one particle per place");
    assert_eq!(welded.spring_count(), indexed.spring_count());
    // It hangs as the indexed mesh does, not as 50 loose triangles falling away.
    assert!(
        (welded_lowest - lowest).abs() < 1e-4,
        "lowest point {welded_lowest} against {lowest}"
    );
    // Split along a UV seam: the middle column's vertices are repeated for the right half.
    let n = 6;
    let seam = 3;
    let mut split = positions.clone();
    let mut copy_of = std::collections::HashMap::new();
    for j in 0..n {
        copy_of.insert(j * n + seam, split.len() as u32);
        split.push(positions[(j * n + seam) as usize]);
    }
    let split_triangles: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            let right = t.iter().any(|&v| v % n > seam);
            t.map(|v| match copy_of.get(&v) {
                Some(&copy) if right => copy,
                _ => v,
            })
        })
        .collect();
    let (seamed, seamed_lowest) = hang_mesh(&split, &split_triangles);
    assert_eq!(seamed.particle_count(), 36);
    assert!((seamed_lowest - lowest).abs() < 1e-4);
}

#[test]
fn an_attached_particle_reaches_its_target_every_step_and_falls_when_let_go() {
    // Every model: the attached corner is at its target at the end of each step, the
    // cloth hangs from it, and once detached it falls freely.
    for model in [
        Model::MassSpring,
        Model::Xpbd(XpbdParams::default()),
        Model::Patches(PatchParams {
            part_width: 2,
            part_height: 2,
            ..PatchParams::default()
        }),
    ] {
        let params = ClothParams {
            model,
            ..ClothParams::seeds()
        };
        let mut cloth = ClothShape::Grid {
            width: 6,
            height: 6,
            spacing: 0.05,
        }
        .build_solver(&ClothPins::None, &params, Affine3A::IDENTITY)
        .unwrap();
        let env = Environment::default();
        for step in 0..60 {
            let target = Vec3::new(0.01 * step as f32, 0.0, 0.0);
            cloth.attach(0, target).unwrap();
            cloth.step(DT, &env);
            assert!(
                cloth.positions()[0].distance(target) < 1e-5,
                "{model:?} step {step}"
            );
        }
        assert_eq!(cloth.attached(), [0]);
        let hanging = cloth.positions()[35].y;
        assert!(hanging < -0.2, "{model:?}: hangs to {hanging}");
        assert!(cloth.detach(0));
        let y0 = cloth.positions()[0].y;
        for _ in 0..10 {
            cloth.step(DT, &env);
        }
        assert!(
            cloth.positions()[0].y < y0 - 0.05,
            "{model:?}: let go, falls"
        );
        assert!(cloth.attach(99, Vec3::ZERO).is_err());
        assert!(cloth.attach(1, Vec3::splat(f32::NAN)).is_err());
    }
}

/// A refusal states its limit from the constant in `limits`, so the message and the
/// check cannot drift apart.
#[test]
fn a_refusal_states_its_limit_from_the_constant() {
    use bevy_cloth::limits::{MAX_NODE_MASS, MAX_POSITION, MIN_NODE_MASS};
    let light = ClothParams {
        node_mass: -1.0,
        ..ClothParams::seeds()
    };
    let e = light.validate().unwrap_err().to_string();
    assert!(e.contains(&format!("{MIN_NODE_MASS:e}")), "{e}");
    assert!(e.contains(&MAX_NODE_MASS.to_string()), "{e}");
    let far = ClothCollider::sphere(2.0 * MAX_POSITION)
        .validate()
        .unwrap_err();
    assert!(
        far.to_string().contains(&format!("{MAX_POSITION:e}")),
        "{far}"
    );
}
