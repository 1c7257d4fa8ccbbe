use bevy::math::Vec3;

use super::*;
use crate::solver::forces::spring_forces;
use crate::solver::unit_hash;

/// Particles at `rest`, each moved up to 2 cm along each axis and given a velocity
/// (both of a hash of its index).
fn jittered(rest: &[Vec3]) -> Particles {
    let mut p = Particles::with_len(rest.len());
    for (i, &x) in rest.iter().enumerate() {
        let jitter = |axis| unit_hash(i, axis) * 0.02;
        p.position[i] = x + Vec3::new(jitter(0), jitter(1), jitter(2));
        p.velocity[i] = Vec3::new(unit_hash(i, 3), unit_hash(i, 4), unit_hash(i, 5));
    }
    p
}

/// `p`'s forces are `general`'s, particle by particle, to rounding (summed in another
/// order), and some are more than 1 N.
fn assert_same_forces(p: &Particles, general: &Particles) {
    for (i, (f, g)) in p.force.iter().zip(&general.force).enumerate() {
        assert!(
            f.distance(*g) < 1e-4 * (1.0 + g.length()),
            "particle {i}: {f} against {g}"
        );
    }
    assert!(general.force.iter().any(|f| f.length() > 1.0));
}

/// The stencil's spring forces on a crumpled, moving 7×5 grid against the general
/// path's, spring by spring (`forces.rs`): the same law, summed in another order.
#[test]
fn the_stencils_spring_forces_are_the_general_paths() {
    let layout = crate::layout::shape::ClothShape::Grid {
        width: 7,
        height: 5,
        spacing: 0.1,
    }
    .layout()
    .unwrap();
    let springs = Springs::from_pairs(layout.springs.clone(), &layout.positions);
    let n = layout.positions.len();
    let mut stencil = Stencil::new(&springs, 7, n).unwrap();
    stencil.sync(&springs);
    let mut p = jittered(&layout.positions);
    let mut general = p.clone();
    let k = [200.0, 50.0, 5.0, 2.0, 0.0];
    stencil.spring_forces(&mut p, |kind| k[kind as usize], 0.3);
    for kind in SpringKind::ALL {
        let range = springs.ranges[kind as usize].clone();
        spring_forces(&springs, &mut general, range, k[kind as usize], 0.3, |_| {
            1.0
        });
    }
    assert_same_forces(&p, &general);
}

/// A strip hanging from its top row, every row below pulled 0.2 m down at once (only
/// the top row's springs stretched, to three times their length): on one thread the
/// limiter goes down the rows in order, so within one sweep the correction travels
/// row after row, past the two rows the bands of [`Projection::across_rows`] reach.
#[test]
fn one_sweep_down_the_rows_carries_a_correction_down_the_strip() {
    let (width, height) = (4, 12);
    let layout = crate::layout::shape::ClothShape::Grid {
        width,
        height,
        spacing: 0.1,
    }
    .layout()
    .unwrap();
    let springs = Springs::from_pairs(layout.springs.clone(), &layout.positions);
    let n = layout.positions.len();
    let mut stencil = Stencil::new(&springs, width as usize, n).unwrap();
    let mut p = Particles::with_len(n);
    let width = width as usize;
    for (i, &x) in layout.positions.iter().enumerate() {
        let top = i < width;
        p.position[i] = if top { x } else { x - Vec3::Y * 0.2 };
        p.inv_mass[i] = if top { 0.0 } else { 1.0 };
    }
    let before = p.position.clone();
    stencil.limit_strain(&mut p, |_| true, 0.1, 1, None, 0.01);
    let rise = |row: usize| p.position[row * width].y - before[row * width].y;
    // Each row after the first takes a share of the correction on its way down.
    for row in 1..=4 {
        assert!(rise(row) > 1e-3, "row {row} rose {} m", rise(row));
    }
}

/// A cone of `around × down` particles (a skirt: a grid wrapped round, its rows
/// closed where the last column meets the first) as a mesh, its vertices numbered
/// `order(i)` for particle `i` of the rows.
fn cone(around: u32, down: u32, order: impl Fn(u32) -> u32) -> crate::solver::Layout {
    let n = around * down;
    let mut points = vec![Vec3::ZERO; n as usize];
    for v in 0..n {
        let (i, j) = (v % around, v / around);
        let a = std::f32::consts::TAU * i as f32 / around as f32;
        let r = 0.2 + 0.03 * j as f32;
        points[order(v) as usize] = Vec3::new(r * a.sin(), -0.05 * j as f32, r * a.cos());
    }
    let mut triangles = Vec::new();
    for j in 0..down - 1 {
        for i in 0..around {
            let (a, b) = (j * around + i, j * around + (i + 1) % around);
            triangles.push([a, a + around, b].map(&order));
            triangles.push([b, a + around, b + around].map(&order));
        }
    }
    crate::solver::Layout::from_mesh(&points, &triangles).unwrap()
}

/// A cone's springs take a stencil over its rows, all but those across its seam
/// (whose ends are more than two columns apart), which are kept apart; the stencil's
/// forces and the general path's over those kept apart are the general path's over
/// every spring, a torn one too. The same cone with its vertices shuffled has no
/// rows: it stays on the general path.
#[test]
fn a_mesh_in_rows_takes_a_stencil_and_keeps_its_seam_apart() {
    let (around, down) = (12u32, 5u32);
    let layout = cone(around, down, |v| v);
    let springs = Springs::from_pairs(layout.springs.clone(), &layout.positions);
    let n = layout.positions.len();
    // A cloth built of it takes the rows.
    assert!(
        crate::solver::structure::Structure::new(layout.clone())
            .rows
            .is_some()
    );
    let mut rows = Rows::find(&springs, n).expect("rows");
    assert_eq!(rows.stencil.width, around as usize);
    let across = |s: usize| {
        let column = |v: u32| v % around;
        column(springs.a[s]).abs_diff(column(springs.b[s])) > 2
    };
    let apart: Vec<usize> = (0..springs.len()).filter(|&s| across(s)).collect();
    assert_eq!(
        rows.apart.iter().map(|&s| s as usize).collect::<Vec<_>>(),
        apart
    );
    assert!(!apart.is_empty() && apart.len() * APART_SHARE <= springs.len());

    let mut springs = springs;
    let torn = 7;
    springs.alive[torn] = false;
    rows.stencil.tear(torn);
    let mut p = jittered(&layout.positions);
    let mut general = p.clone();
    let k = [200.0, 50.0, 5.0, 2.0, 0.0];
    rows.stencil
        .spring_forces(&mut p, |kind| k[kind as usize], 0.3);
    for kind in SpringKind::ALL {
        let k = k[kind as usize];
        let range = springs.ranges[kind as usize].clone();
        let kept = rows.apart.iter().map(|&s| s as usize);
        let kept = kept.filter(|s| range.contains(s));
        spring_forces(&springs, &mut p, kept, k, 0.3, |_| 1.0);
        spring_forces(&springs, &mut general, range, k, 0.3, |_| 1.0);
    }
    assert_same_forces(&p, &general);

    let mut order: Vec<u32> = (0..around * down).collect();
    order.sort_by(|&u, &v| unit_hash(u as usize, 9).total_cmp(&unit_hash(v as usize, 9)));
    let shuffled = cone(around, down, |v| order[v as usize]);
    let springs = Springs::from_pairs(shuffled.springs, &shuffled.positions);
    assert!(Rows::find(&springs, n).is_none());
}
