//! What several test files share (each uses part of it).
#![allow(dead_code)]

pub mod golden;

use bevy::math::{Affine3A, Vec3A};
use bevy::mesh::{Mesh, VertexAttributeValues};
use bevy::prelude::*;
use bevy_cloth::params::{Environment, Integrator, Model, SpringFamily, SpringParams, Substeps};
use bevy_cloth::prelude::*;
use bevy_cloth::solver::{ClothSolver, Layout, ProxyBinding, SpringKind};

/// A cloth of 6 × 6 particles 4 cm apart, without air drag, and where it lies flat (in
/// xz) with its middle at `centre`: on a platform's top at y = 0.1, `centre.y` = 0.106 puts
/// it at the platform's 5 mm thickness and 1 mm.
pub fn lying_cloth(centre: Vec3) -> (Cloth, Transform) {
    let cloth = Cloth::grid(6, 6, 0.04)
        .with_pins(ClothPins::None)
        .with_params(ClothParams {
            drag: 0.0,
            ..ClothParams::seeds()
        });
    let place = Transform::from_translation(centre)
        .with_rotation(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2));
    (cloth, place)
}

/// The mean position of a cloth's particles.
pub fn centroid(cloth: &ClothSolver) -> Vec3 {
    cloth.positions().iter().sum::<Vec3>() / cloth.positions().len() as f32
}

/// [`centroid`] of a cloth entity's simulation.
pub fn entity_centroid(app: &App, cloth: Entity) -> Vec3 {
    centroid(&app.world().get::<ClothSimulation>(cloth).unwrap().solver)
}

/// How many of the cloths' edges (their structural and shear springs) pass through a
/// triangle (of any of them) that does not share a particle with them: an exact
/// segment–triangle test over every pair, with a box test first.
pub fn edges_through_triangles(cloths: &[&ClothSolver]) -> usize {
    let mut x: Vec<Vec3A> = Vec::new();
    let mut edges: Vec<[u32; 2]> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    // A garment's seams join two particles (one per piece) that sewing brings to one
    // point: they count as one vertex here (an edge at one end of a seam and a triangle
    // at the other share a corner, not a crossing).
    let mut same: Vec<u32> = Vec::new();
    for cloth in cloths {
        let offset = x.len() as u32;
        x.extend(cloth.positions().iter().map(|&p| Vec3A::from(p)));
        let springs = cloth.springs();
        same.extend((0..cloth.particle_count() as u32).map(|i| i + offset));
        for s in springs.ranges[SpringKind::Seam as usize].clone() {
            let (a, b) = (springs.a[s] + offset, springs.b[s] + offset);
            let (ra, rb) = (root(&same, a), root(&same, b));
            same[ra.max(rb) as usize] = ra.min(rb);
        }
        edges.extend(
            [SpringKind::Structural, SpringKind::Shear]
                .into_iter()
                .flat_map(|kind| springs.ranges[kind as usize].clone())
                .filter(|&s| springs.alive[s])
                .map(|s| [springs.a[s] + offset, springs.b[s] + offset]),
        );
        triangles.extend(cloth.triangles().iter().map(|t| t.map(|i| i + offset)));
    }
    let boxes = |ids: &[u32]| {
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        for &i in ids {
            lo = lo.min(x[i as usize]);
            hi = hi.max(x[i as usize]);
        }
        (lo, hi)
    };
    let edge_boxes: Vec<_> = edges.iter().map(|e| boxes(e)).collect();
    let mut crossing = 0;
    for t in &triangles {
        let (lo, hi) = boxes(t);
        for (e, (elo, ehi)) in edges.iter().zip(&edge_boxes) {
            if elo.cmpgt(hi).any() || ehi.cmplt(lo).any() {
                continue;
            }
            let corners = t.map(|i| root(&same, i));
            if corners.contains(&root(&same, e[0])) || corners.contains(&root(&same, e[1])) {
                continue;
            }
            let [a, b, c] = t.map(|i| x[i as usize]);
            if segment_hits_triangle(x[e[0] as usize], x[e[1] as usize], a, b, c) {
                crossing += 1;
            }
        }
    }
    crossing
}

/// The representative of `i` among the particles joined by seams (union–find).
fn root(same: &[u32], mut i: u32) -> u32 {
    while same[i as usize] != i {
        i = same[i as usize];
    }
    i
}

/// Whether the segment `p–q` meets the triangle `abc` (Möller–Trumbore with the
/// segment's parameter in [0, 1]).
pub fn segment_hits_triangle(p: Vec3A, q: Vec3A, a: Vec3A, b: Vec3A, c: Vec3A) -> bool {
    let (dir, e1, e2) = (q - p, b - a, c - a);
    let h = dir.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-12 {
        return false;
    }
    let s = p - a;
    let u = s.dot(h) / det;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let qv = s.cross(e1);
    let v = dir.dot(qv) / det;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = e2.dot(qv) / det;
    (0.0..=1.0).contains(&t)
}

// ----- headless apps -----------------------------------------------------------------

pub fn app() -> App {
    bevy_cloth::headless::headless_app()
}

/// The seeds' parameters (`ClothParams::seeds`): automatic substeps keep them stable.
pub fn quiet_params() -> ClothParams {
    ClothParams::seeds()
}

pub fn sim_time(app: &App, e: Entity) -> f32 {
    app.world().get::<ClothSimulation>(e).unwrap().solver.time()
}

/// A 5×4 cloth 2 m up, after two updates: its entity and the mesh the plugin made.
pub fn spawn_small_cloth(app: &mut App) -> (Entity, Handle<Mesh>) {
    let e = app
        .world_mut()
        .spawn((
            Cloth::grid(5, 4, 0.1).with_params(quiet_params()),
            Transform::from_xyz(0.0, 2.0, 0.0),
        ))
        .id();
    app.update();
    app.update();
    let handle = app
        .world()
        .get::<Mesh3d>(e)
        .expect("the plugin adds a mesh")
        .0
        .clone();
    (e, handle)
}

/// The positions in a mesh.
pub fn mesh_positions(app: &App, handle: &Handle<Mesh>) -> Vec<[f32; 3]> {
    let mesh = app.world().resource::<Assets<Mesh>>().get(handle).unwrap();
    match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
        Some(VertexAttributeValues::Float32x3(p)) => p.clone(),
        _ => panic!("no positions"),
    }
}

// ----- solvers ---------------------------------------------------------------------

pub const DT: f32 = 0.016;

pub fn no_springs() -> SpringParams {
    SpringParams {
        structural: SpringFamily::off(100.0),
        shear: SpringFamily::off(50.0),
        bend: SpringFamily::off(50.0),
        bend_diagonal: SpringFamily::off(25.0),
        seam: SpringFamily::off(100.0),
        ..SpringParams::default()
    }
}

/// Parameters with every dissipative or corrective term off.
pub fn conservative(integrator: Integrator) -> ClothParams {
    ClothParams {
        model: Model::MassSpring,
        node_mass: 1e-3,
        springs: SpringParams::from_structural(50.0),
        drag: 0.0,
        integrator,
        substeps: Substeps::Auto { max: 8192 },
        strain_limit: None,
        strain_limit_iterations: 0,
        strain_limit_tolerance: None,
        tear_ratio: None,
        self_collision: Default::default(),
        fabric: None,
        still_air: false,
        max_depenetration_speed: 1.0,
        teleport: Default::default(),
        inertia: Default::default(),
    }
}

pub fn no_wind() -> Environment {
    Environment::default()
}

/// Four unpinned particles with no springs: each falls freely, one substep per step.
pub fn free_particles(integrator: Integrator) -> ClothSolver {
    free_particles_at(integrator, 1, Affine3A::IDENTITY)
}

/// Four unconnected particles placed by `frame`, stepped in `substeps` substeps.
pub fn free_particles_at(integrator: Integrator, substeps: u32, frame: Affine3A) -> ClothSolver {
    let params = ClothParams {
        springs: no_springs(),
        substeps: Substeps::Fixed(substeps),
        ..conservative(integrator)
    };
    let shape = ClothShape::Grid {
        width: 2,
        height: 2,
        spacing: 0.1,
    };
    shape
        .build_solver(&ClothPins::None, &params, frame)
        .unwrap()
}

/// A cloth held at two corners, released horizontal so it swings.
pub fn swinging_cloth(params: &ClothParams) -> ClothSolver {
    let frame = Affine3A::from_rotation_translation(
        Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
        Vec3::new(0.0, 1.0, 0.0),
    );
    ClothShape::Grid {
        width: 8,
        height: 8,
        spacing: 0.1,
    }
    .build_solver(&ClothPins::TopCorners, params, frame)
    .unwrap()
}

pub fn corner_hung_grid_with(width: u32, height: u32, params: &ClothParams) -> ClothSolver {
    ClothShape::Grid {
        width,
        height,
        spacing: 0.02,
    }
    .build_solver(&ClothPins::TopCorners, params, Affine3A::IDENTITY)
    .unwrap()
}

/// How a proxy-drawn cloth's render mesh (its positions `drawn`) sits on `binding`: the
/// farthest any vertex is from its bound point over `solver`'s particles (taken into the
/// cloth's frame), and the most any has moved from `start`.
pub fn proxy_offsets(
    solver: &ClothSolver,
    binding: &ProxyBinding,
    drawn: &[[f32; 3]],
    start: &[Vec3],
) -> (f32, f32) {
    let to_local = solver.frame().inverse();
    let local: Vec<Vec3> = solver
        .positions()
        .iter()
        .map(|&x| to_local.transform_point3(x))
        .collect();
    let farthest = drawn
        .iter()
        .enumerate()
        .map(|(v, p)| Vec3::from(*p).distance(binding.point(&local, v)))
        .fold(0.0, f32::max);
    let moved = drawn
        .iter()
        .zip(start)
        .map(|(p, r)| Vec3::from(*p).distance(*r))
        .fold(0.0, f32::max);
    (farthest, moved)
}

/// A `width × height` mesh `spacing` m apart whose inner vertices are moved up to a third of
/// the spacing, each cell split along a diagonal chosen by a hash: irregular triangles,
/// springs of unequal lengths and directions, no two cells alike.
pub fn irregular_mesh(width: u32, height: u32, spacing: f32) -> Layout {
    let hash = |i: u32, salt: u32| {
        let h = (i.wrapping_mul(0x9e37_79b9) ^ salt.wrapping_mul(0x85eb_ca6b))
            .wrapping_mul(0xc2b2_ae35);
        (h >> 8) as f32 / (1u32 << 24) as f32 - 0.5
    };
    let positions: Vec<Vec3> = (0..width * height)
        .map(|v| {
            let (i, j) = (v % width, v / width);
            let inner = i > 0 && j > 0 && i + 1 < width && j + 1 < height;
            let jitter = if inner {
                Vec3::new(hash(v, 1), hash(v, 2), 0.0) * (spacing * 0.67)
            } else {
                Vec3::ZERO
            };
            Vec3::new(i as f32, -(j as f32), 0.0) * spacing + jitter
        })
        .collect();
    let mut triangles = Vec::new();
    for j in 0..height - 1 {
        for i in 0..width - 1 {
            let (a, b) = (j * width + i, j * width + i + 1);
            let (c, d) = (a + width, b + width);
            if hash(a, 3) < 0.0 {
                triangles.extend([[a, c, b], [b, c, d]]);
            } else {
                triangles.extend([[a, c, d], [a, d, b]]);
            }
        }
    }
    Layout::from_mesh(&positions, &triangles).unwrap()
}
