//! What drawing a crowd's proxies costs the app: 100 cloths of 16 × 24 particles in the
//! headless app (`ClothPlugin`, interpolation on, so every cloth is written every frame),
//! each drawn through a proxy mesh 3 × 3 finer (3,358 vertices a cloth). Times the
//! plugin's `ClothSystems::WriteMesh` (normals, every proxy vertex placed, handed to the
//! meshes) against the fixed update (the cloths' step), each frame, over 120 frames
//! after 30: medians and p10–p90.
//!
//! `cargo run -p bevy_cloth_lab --example proxy_draw`
use std::time::Instant;

use bevy::prelude::*;
use bevy_cloth::ClothSystems;
use bevy_cloth::headless::headless_app;
use bevy_cloth::prelude::*;

#[derive(Resource, Default)]
struct Clock {
    start: Option<Instant>,
    write: Vec<f64>,
    fixed_start: Option<Instant>,
    fixed: Vec<f64>,
}

fn main() {
    let mut app = headless_app();
    time_drawing_and_step(&mut app);
    let cloths = spawn_proxied_cloths(&mut app);
    // A breeze across them, so the cloths swing (and are written) every frame.
    app.insert_resource(ClothEnvironment(bevy_cloth::params::Environment {
        air: Some(Air {
            velocity: Vec3::new(0.0, 0.0, 4.0),
            ..default()
        }),
        ..default()
    }));
    for _ in 0..30 {
        app.update();
    }
    let mut clock = app.world_mut().resource_mut::<Clock>();
    clock.write.clear();
    clock.fixed.clear();
    for _ in 0..120 {
        app.update();
    }
    let stable = cloths.iter().all(|&c| {
        let sim = app.world().get::<ClothSimulation>(c).expect("built");
        sim.solver.is_stable()
    });
    assert!(stable, "a cloth failed: not timed");
    let clock = app.world().resource::<Clock>();
    let stats = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
        (at(0.5), at(0.1), at(0.9))
    };
    let fixed: Vec<f64> = clock.fixed.iter().copied().filter(|&ms| ms > 0.0).collect();
    let (wm, w10, w90) = stats(&clock.write);
    let (fm, f10, f90) = stats(&fixed);
    println!(
        "compute pool of {} thread(s) beside the main one: drawing (WriteMesh) {wm:.2} ms \
         ({w10:.2}–{w90:.2}); fixed update {fm:.2} ms ({f10:.2}–{f90:.2}); drawing against \
         the step {:.0}%",
        bevy::tasks::ComputeTaskPool::get().thread_num(),
        100.0 * wm / fm
    );
}

/// Times `ClothSystems::WriteMesh` and the fixed update every frame into [`Clock`].
fn time_drawing_and_step(app: &mut App) {
    app.init_resource::<Clock>()
        .add_systems(
            PostUpdate,
            (
                (|mut c: ResMut<Clock>| c.start = Some(Instant::now()))
                    .before(ClothSystems::WriteMesh),
                (|mut c: ResMut<Clock>| {
                    let ms = c.start.map_or(0.0, |s| s.elapsed().as_secs_f64() * 1e3);
                    c.write.push(ms);
                })
                .after(ClothSystems::WriteMesh),
            ),
        )
        .add_systems(
            RunFixedMainLoop,
            (
                (|mut c: ResMut<Clock>| c.fixed_start = Some(Instant::now()))
                    .in_set(RunFixedMainLoopSystems::BeforeFixedMainLoop),
                (|mut c: ResMut<Clock>| {
                    let ms = c
                        .fixed_start
                        .map_or(0.0, |s| s.elapsed().as_secs_f64() * 1e3);
                    c.fixed.push(ms);
                })
                .in_set(RunFixedMainLoopSystems::AfterFixedMainLoop),
            ),
        );
}

/// 100 cloths of 16 × 24 hung from their top rows on a 10 × 10 grid, each drawn
/// through a proxy 3 × 3 finer once it is built.
fn spawn_proxied_cloths(app: &mut App) -> Vec<Entity> {
    let (w, h) = (16u32, 24u32);
    let cloths: Vec<Entity> = (0..100)
        .map(|c| {
            let at = Vec3::new((c % 10) as f32, 2.0, (c / 10) as f32);
            app.world_mut()
                .spawn((
                    Cloth::grid(w, h, 0.035).with_pins(ClothPins::TopRow),
                    Transform::from_translation(at).with_rotation(Quat::from_rotation_y(0.3)),
                ))
                .id()
        })
        .collect();
    while cloths
        .iter()
        .any(|&c| app.world().get::<ClothSimulation>(c).is_none())
    {
        app.update();
    }
    for &cloth in &cloths {
        let sim = app.world().get::<ClothSimulation>(cloth).expect("built");
        let mesh = finer_grid(sim.solver.rest_positions(), (w, h), 3);
        let handle = app.world_mut().resource_mut::<Assets<Mesh>>().add(mesh);
        app.world_mut()
            .entity_mut(cloth)
            .insert(ClothProxy { mesh: handle });
    }
    cloths
}

/// A render mesh `k` times finer each way than a `w × h` grid with rest positions `rest`.
fn finer_grid(rest: &[Vec3], (w, h): (u32, u32), k: u32) -> Mesh {
    let (rw, rh) = ((w - 1) * k + 1, (h - 1) * k + 1);
    let mut positions = Vec::new();
    for j in 0..rh {
        for i in 0..rw {
            let (ci, cj) = ((i / k).min(w - 2), (j / k).min(h - 2));
            let (a, b) = (
                (i - ci * k) as f32 / k as f32,
                (j - cj * k) as f32 / k as f32,
            );
            let at = |di: u32, dj: u32| rest[((cj + dj) * w + ci + di) as usize];
            positions.push(
                at(0, 0)
                    .lerp(at(1, 0), a)
                    .lerp(at(0, 1).lerp(at(1, 1), a), b)
                    .to_array(),
            );
        }
    }
    let n = positions.len();
    let mut indices = Vec::new();
    for j in 0..rh - 1 {
        for i in 0..rw - 1 {
            let v = j * rw + i;
            indices.extend([v, v + rw, v + 1, v + 1, v + rw, v + rw + 1]);
        }
    }
    Mesh::new(
        bevy::mesh::PrimitiveTopology::TriangleList,
        bevy::asset::RenderAssetUsages::default(),
    )
    .with_inserted_attribute(Mesh::ATTRIBUTE_POSITION, positions)
    .with_inserted_attribute(Mesh::ATTRIBUTE_NORMAL, vec![[0.0f32, 0.0, 1.0]; n])
    .with_inserted_indices(bevy::mesh::Indices::U32(indices))
}
