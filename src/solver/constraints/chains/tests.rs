//! The line solve against a dense solve, and its lanes against one line at a time.

use super::*;

/// The linearised XPBD system of a chain, `(J W Jᵀ + α̃) Δλ = −C`, assembled densely
/// and solved by Gaussian elimination in `f64`: each particle's move `W Jᵀ Δλ`.
fn dense_moves(x: &[Vec3], w: &[f32], rest: &[f32], compliance: f64) -> Vec<[f64; 3]> {
    let m = rest.len();
    let f = |v: Vec3| [v.x, v.y, v.z].map(f64::from);
    let n: Vec<[f64; 3]> = (0..m)
        .map(|k| {
            let d = f(x[k + 1] - x[k]);
            let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            d.map(|c| c / len)
        })
        .collect();
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let mut a = vec![vec![0.0f64; m + 1]; m];
    for k in 0..m {
        let (wa, wb) = (f64::from(w[k]), f64::from(w[k + 1]));
        a[k][k] = wa + wb + compliance;
        if k + 1 < m {
            let off = -f64::from(w[k + 1]) * dot(n[k], n[k + 1]);
            (a[k][k + 1], a[k + 1][k]) = (off, off);
        }
        let len = dot(f(x[k + 1] - x[k]), n[k]);
        a[k][m] = -(len - f64::from(rest[k]));
    }
    for c in 0..m {
        let pivot = (c..m).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()));
        a.swap(c, pivot.unwrap());
        let pivot_row = a[c].clone();
        for (r, row) in a.iter_mut().enumerate() {
            if r != c {
                let factor = row[c] / pivot_row[c];
                for (x, p) in row[c..].iter_mut().zip(&pivot_row[c..]) {
                    *x -= factor * p;
                }
            }
        }
    }
    let lambda: Vec<f64> = (0..m).map(|k| a[k][m] / a[k][k]).collect();
    (0..=m)
        .map(|i| {
            let mut d = [0.0; 3];
            for c in 0..3 {
                if i > 0 {
                    d[c] += n[i - 1][c] * lambda[i - 1];
                }
                if i < m {
                    d[c] -= n[i][c] * lambda[i];
                }
                d[c] *= f64::from(w[i]);
            }
            d
        })
        .collect()
}

/// A bent, stretched chain of `count` particles.
fn bent_chain(count: usize) -> Vec<Vec3> {
    (0..count)
        .map(|i| {
            let t = i as f32;
            Vec3::new(0.11 * t, -0.02 * t * t, 0.013 * (t * 1.7).sin())
        })
        .collect()
}

fn tile_solve(x: &[Vec3], w: &[f32], rest: &[f32], family: Family) -> Vec<Vec3> {
    // One chain in lane 3 of a tile, the other lanes padding.
    let (m, j) = (x.len(), 3);
    let mut rows = vec![Row::default(); m];
    for (k, row) in rows.iter_mut().enumerate() {
        (row.x[0][j], row.x[1][j], row.x[2][j]) = (x[k].x, x[k].y, x[k].z);
        row.w[j] = w[k];
        row.rest[j] = rest.get(k).copied().unwrap_or(0.0);
        row.live[j] = f32::from(u8::from(k + 1 < m));
    }
    solve_tile::<false>(&mut rows, family);
    for row in &rows {
        for (lane, c) in row.x.iter().flatten().enumerate() {
            assert!(lane % LANES == j || *c == 0.0, "padding moved");
        }
    }
    rows.iter()
        .map(|row| Vec3::new(row.x[0][j], row.x[1][j], row.x[2][j]))
        .collect()
}

#[test]
fn a_chain_is_solved_as_its_dense_linear_system() {
    let x = bent_chain(9);
    // Rest lengths 3% to 10% below the current ones, the first particle pinned and
    // the masses uneven.
    let rest: Vec<f32> = (0..8)
        .map(|k| x[k].distance(x[k + 1]) * (0.9 + 0.01 * k as f32))
        .collect();
    let w: Vec<f32> = (0..9)
        .map(|i| if i == 0 { 0.0 } else { 1.0 + 0.3 * i as f32 })
        .collect();
    for compliance in [0.0, 0.5, 40.0] {
        let family = Family {
            on: true,
            compliance,
            damping: 0.0,
            max_stretch: f32::INFINITY,
        };
        let moves = tile_solve(&x, &w, &rest, family);
        let expected = dense_moves(&x, &w, &rest, f64::from(compliance));
        for (i, (got, want)) in moves.iter().zip(&expected).enumerate() {
            for c in 0..3 {
                let error = (f64::from(got[c]) - want[c]).abs();
                assert!(
                    error < 2e-6,
                    "α̃ {compliance}, particle {i}: {got} against {want:?}"
                );
            }
        }
        assert_eq!(moves[0], Vec3::ZERO, "the pinned particle moved");
    }
}

#[test]
fn repeated_solves_converge_on_an_inextensible_chain_as_newton_does() {
    // Each solve is a Newton step on the chain's lengths (Goldenthal et al. 2007's
    // fast projection): the error left falls quadratically, solve after solve.
    let mut y = bent_chain(17);
    let rest: Vec<f32> = (0..16).map(|k| y[k].distance(y[k + 1]) * 0.98).collect();
    let w = vec![1.0; 17];
    let family = Family {
        on: true,
        ..Family::default()
    };
    let error = |y: &[Vec3]| {
        (0..16)
            .map(|k| (y[k].distance(y[k + 1]) - rest[k]).abs() / rest[k])
            .fold(0.0f32, f32::max)
    };
    let mut errors = vec![error(&y)];
    for _ in 0..3 {
        let moves = tile_solve(&y, &w, &rest, family);
        y.iter_mut().zip(&moves).for_each(|(a, b)| *a += *b);
        errors.push(error(&y));
    }
    println!("largest length error, solve after solve: {errors:?}");
    // From 2% off (1.4% after the first solve, which turns the links a long way),
    // then quadratically: 1.8e-4, 5.8e-7.
    assert!(errors[1] < errors[0], "{errors:?}");
    assert!(errors[2] < errors[1] * 0.05, "{errors:?}");
    assert!(
        errors[3] < errors[2] * 0.05 && errors[3] < 1e-6,
        "{errors:?}"
    );
}

#[test]
fn a_grid_is_covered_by_its_rows_then_its_columns() {
    let (width, height) = (7usize, 5usize);
    let positions: Vec<Vec3> = (0..width * height)
        .map(|i| Vec3::new((i % width) as f32 * 0.1, -((i / width) as f32) * 0.1, 0.0))
        .collect();
    let mut pairs = Vec::new();
    for r in 0..height {
        for c in 0..width {
            let i = (r * width + c) as u32;
            if c + 1 < width {
                pairs.push((SpringKind::Structural, i, i + 1));
            }
            if r + 1 < height {
                pairs.push((SpringKind::Structural, i, i + width as u32));
            }
            if c + 1 < width && r + 1 < height {
                pairs.push((SpringKind::Shear, i, i + width as u32 + 1));
            }
        }
    }
    let springs = Springs::from_pairs(pairs, &positions);
    let chains = Chains::new(&springs, &positions);
    assert_eq!(chains.sets.len(), 2, "rows and columns");
    let structural = springs.ranges[SpringKind::Structural as usize].len();
    assert_eq!(
        chains.counts(),
        (2, structural),
        "every structural spring once"
    );
    // Rows first: the first set's constraints join neighbours in a row.
    let (rows, columns) = (&chains.sets[0], &chains.sets[1]);
    assert_eq!(rows.mean_step(), 1.0);
    assert_eq!(columns.mean_step(), width as f64);
    // Whole lines: a row's particles in one chain of `width`, a column's of `height`.
    assert_eq!(rows.tiles[0].1, width);
    assert_eq!(columns.tiles[0].1, height);
}

#[test]
fn the_strain_limit_along_a_chain_takes_back_only_what_is_past_it() {
    // A straight chain pinned at its first particle, its links 2%, 30%, 25%, 5% and 40%
    // past their rest lengths: under a 10% limit along the chain, the three past it
    // come back to 110% (exactly, a straight chain being linear), the two within it keep
    // their lengths.
    let stretch = [1.02f32, 1.3, 1.25, 1.05, 1.4];
    let mut y = vec![Vec3::ZERO];
    for s in stretch {
        y.push(*y.last().unwrap() + Vec3::new(0.1 * s, 0.0, 0.0));
    }
    let rest = vec![0.1f32; stretch.len()];
    let mut w = vec![1.0f32; y.len()];
    w[0] = 0.0;
    let limit = Family::limit(1.1);
    assert!(limit.limit_only());
    let moves = tile_solve(&y, &w, &rest, limit);
    y.iter_mut().zip(&moves).for_each(|(a, b)| *a += *b);
    let got: Vec<f32> = (0..stretch.len())
        .map(|k| y[k].distance(y[k + 1]) / rest[k])
        .collect();
    println!("stretches after the limit: {got:?}");
    for (k, (&g, &s)) in got.iter().zip(&stretch).enumerate() {
        let want = s.min(1.1);
        assert!((g - want).abs() < 1e-5, "link {k}: {g} against {want}");
    }
}
