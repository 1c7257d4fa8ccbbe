//! Grid cloths as stencils: every spring of a grid joins particle `a` to `a + step` for
//! one of a few offsets (structural, shear, bend, diagonal bend), so each offset's
//! springs are read and written as two shifted slices of the particle arrays, with no
//! index lists, no per-spring bounds checks and no scatter through indices.
//!
//! The [`Springs`] stay the truth (tearing, counts, faces, the general path for meshes
//! and garments); a stencil mirrors their rest lengths and weights (stiffness factor ×
//! alive) per offset, synced when they change.
//!
//! The strain limiter on a stencil is a coloured Gauss–Seidel: within one colour (an
//! offset's springs starting on even or on odd columns or rows) no two springs share a
//! particle, so its corrections do not depend on the order they are made in. The two
//! diagonals of one band of rows are corrected together (Jacobi, summed), so a mirror
//! image of the cloth is corrected as the mirror image (for an even width).

use bevy::math::Vec3;

use super::{Particles, SpringKind, Springs};

/// One stencil offset: the springs `(a, a + step)` of one family.
#[derive(Clone, Debug)]
struct Offset {
    kind: SpringKind,
    /// Column offset of `b` from `a` (−2…2).
    dx: isize,
    /// Row offset (0, 1 or 2).
    dy: usize,
    /// `b − a` in particle indices.
    step: usize,
    /// Rest length of the spring from `a` (0 where there is none), indexed by `a`.
    rest: Vec<f32>,
    /// Stiffness factor × alive of the spring from `a` (0 where there is none or it
    /// tore), indexed by `a`.
    weight: Vec<f32>,
}

/// A grid cloth's springs as stencil offsets.
#[derive(Clone, Debug)]
pub(super) struct Stencil {
    width: usize,
    offsets: Vec<Offset>,
    /// For each spring: its offset and `a`, to follow tearing.
    slot: Vec<(u8, u32)>,
    /// One force per spring of an offset, or the limiter's corrections of two offsets,
    /// reused.
    scratch: Vec<Vec3>,
}

impl Stencil {
    /// The stencil of `springs` on a `width`-wide grid of `n` particles, or `None` when a
    /// spring is not a grid offset (a seam, a welded mesh) or two share a slot.
    pub fn new(springs: &Springs, width: usize, n: usize) -> Option<Self> {
        let mut offsets: Vec<Offset> = Vec::new();
        let mut slot = Vec::with_capacity(springs.len());
        for s in 0..springs.len() {
            let kind = springs.kind(s);
            if kind == SpringKind::Seam {
                return None;
            }
            let (mut a, mut b) = (springs.a[s] as usize, springs.b[s] as usize);
            if b < a {
                std::mem::swap(&mut a, &mut b);
            }
            let dy = b / width - a / width;
            let dx = (b % width) as isize - (a % width) as isize;
            if dy > 2 || dx.abs() > 2 {
                return None;
            }
            let index = match offsets
                .iter()
                .position(|o| o.kind == kind && o.dx == dx && o.dy == dy)
            {
                Some(index) => index,
                None => {
                    let step = b - a;
                    offsets.push(Offset {
                        kind,
                        dx,
                        dy,
                        step,
                        rest: vec![0.0; n - step],
                        weight: vec![0.0; n - step],
                    });
                    offsets.len() - 1
                }
            };
            let offset = &mut offsets[index];
            if offset.rest[a] != 0.0 {
                return None;
            }
            offset.rest[a] = springs.rest_length[s];
            slot.push((index as u8, a as u32));
        }
        let mut stencil = Self {
            width,
            offsets,
            slot,
            scratch: vec![Vec3::ZERO; 2 * n],
        };
        stencil.sync(springs);
        Some(stencil)
    }

    /// Takes the springs' rest lengths, stiffness factors and alive flags.
    pub fn sync(&mut self, springs: &Springs) {
        for (s, &(o, a)) in self.slot.iter().enumerate() {
            let offset = &mut self.offsets[o as usize];
            offset.rest[a as usize] = springs.rest_length[s];
            offset.weight[a as usize] = if springs.alive[s] {
                springs.scale(s)
            } else {
                0.0
            };
        }
    }

    /// Spring `s` tore.
    pub fn tear(&mut self, s: usize) {
        let (o, a) = self.slot[s];
        self.offsets[o as usize].weight[a as usize] = 0.0;
    }

    /// Adds every spring's Hooke force `k (|l| − l0) l/|l|` plus damping along it
    /// (the general path's law, `forces.rs`) to `p.force`; `k` per family.
    pub fn spring_forces(
        &mut self,
        p: &mut Particles,
        k: impl Fn(SpringKind) -> f32,
        damping: f32,
    ) {
        let n = p.len();
        for offset in &self.offsets {
            let k = k(offset.kind);
            if k == 0.0 {
                continue;
            }
            let m = n - offset.step;
            let pairs = self.scratch[..m]
                .iter_mut()
                .zip(offset.rest.iter().zip(&offset.weight))
                .zip(p.position[..m].iter().zip(&p.position[offset.step..]))
                .zip(p.velocity[..m].iter().zip(&p.velocity[offset.step..]));
            for (((f, (&rest, &weight)), (&xa, &xb)), (&va, &vb)) in pairs {
                let d = xb - xa;
                let len = d.length();
                let live = weight != 0.0 && len > f32::EPSILON;
                let dir = d / if live { len } else { 1.0 };
                let magnitude = k * weight * (len - rest) + damping * (vb - va).dot(dir);
                *f = if live { dir * magnitude } else { Vec3::ZERO };
            }
            for (force, f) in p.force[..m].iter_mut().zip(&self.scratch[..m]) {
                *force += *f;
            }
            for (force, f) in p.force[offset.step..].iter_mut().zip(&self.scratch[..m]) {
                *force -= *f;
            }
        }
    }

    /// One sweep of Provot's strain limit over the enabled `kinds`' springs, colour by
    /// colour (see the module doc). With `TRACK`, returns whether a spring was longer than
    /// `past·l0`.
    pub fn limit_strain_sweep<const TRACK: bool>(
        &mut self,
        p: &mut Particles,
        enabled: impl Fn(SpringKind) -> bool,
        limit: f32,
        past: f32,
        h: f32,
    ) -> bool {
        let limited = |o: &&Offset| {
            matches!(o.kind, SpringKind::Structural | SpringKind::Shear) && enabled(o.kind)
        };
        // At most two offsets per colour: the row springs, the column springs, the two
        // diagonals.
        let pick = |keep: &dyn Fn(&Offset) -> bool| {
            let mut found = self.offsets.iter().filter(limited).filter(|o| keep(o));
            [found.next(), found.next()]
        };
        let along = pick(&|o| o.dy == 0);
        let down = pick(&|o| o.dy == 1 && o.dx == 0);
        let diagonal = pick(&|o| o.dy == 1 && o.dx != 0);
        let colour = Colour {
            width: self.width,
            limit,
            past,
            h,
        };
        let scratch = &mut self.scratch;
        let mut unconverged = false;
        for parity in 0..2 {
            for o in along.iter().flatten() {
                unconverged |= colour.limit::<TRACK>(p, [Some(o), None], 1, parity, scratch);
            }
        }
        for parity in 0..2 {
            for o in down.iter().flatten() {
                unconverged |= colour.limit::<TRACK>(p, [Some(o), None], 2, parity, scratch);
            }
            unconverged |= colour.limit::<TRACK>(p, diagonal, 2, parity, scratch);
        }
        unconverged
    }
}

/// The numbers one colour of the limiter needs.
struct Colour {
    width: usize,
    limit: f32,
    past: f32,
    h: f32,
}

impl Colour {
    /// The spring starts `a` of one colour of an offset (`m` of them in all): every
    /// other particle (`rows` 1), or every particle of every other row (`rows` 2),
    /// starting at `parity`.
    fn starts(&self, rows: usize, parity: usize, m: usize) -> impl Iterator<Item = usize> {
        let w = self.width;
        let (step, len) = if rows == 1 { (2, 1) } else { (2 * w, w) };
        (parity * len..m)
            .step_by(step)
            .flat_map(move |first| first..(first + len).min(m))
    }

    /// Limits the springs of `offsets` of one colour: every correction from the positions
    /// before any of them (within one offset no two springs share a particle, and two
    /// offsets are summed), then applied to positions and velocities by inverse mass.
    fn limit<const TRACK: bool>(
        &self,
        p: &mut Particles,
        offsets: [Option<&Offset>; 2],
        rows: usize,
        parity: usize,
        scratch: &mut [Vec3],
    ) -> bool {
        let mut unconverged = false;
        let n = p.len();
        for (o, corrections) in offsets.iter().flatten().zip(scratch.chunks_mut(n)) {
            for a in self.starts(rows, parity, n - o.step) {
                let b = a + o.step;
                let (wa, wb) = (p.inv_mass[a], p.inv_mass[b]);
                let mut correction = Vec3::ZERO;
                if o.weight[a] != 0.0 && wa + wb != 0.0 {
                    let d = p.position[b] - p.position[a];
                    let len = d.length();
                    let max = (1.0 + self.limit) * o.rest[a];
                    if TRACK {
                        unconverged |= len > self.past * o.rest[a];
                    }
                    if len > max {
                        correction = d * ((len - max) / (len * (wa + wb)));
                    }
                }
                corrections[a] = correction;
            }
        }
        for (o, corrections) in offsets.iter().flatten().zip(scratch.chunks(n)) {
            for a in self.starts(rows, parity, n - o.step) {
                let b = a + o.step;
                let c = corrections[a];
                let (wa, wb) = (p.inv_mass[a], p.inv_mass[b]);
                p.position[a] += c * wa;
                p.position[b] -= c * wb;
                p.velocity[a] += c * (wa / self.h);
                p.velocity[b] -= c * (wb / self.h);
            }
        }
        unconverged
    }
}
