//! The hybrid patch model (Sladović 2014 §3.4): the grid is split into parts of w×h particles;
//! the parts' centres of mass form a mass-spring lattice (a [`ClothSolver`] of its own, each
//! node a represents of its particles) that feels gravity, wind, drag and the part springs; the
//! particles follow targets interpolated between neighbouring part centres.
//!
//! Coupling rule (the thesis warns that parts fly apart when the two are not matched):
//! the coupling is one-way. External forces act on the part centres, which carry the
//! particles' mass; particles feel only the pull toward their targets, damped at a
//! fraction of critical (`2√(α m)`) on their velocity *relative to the target*, so they
//! follow their parts without a hidden drag and cannot push them apart. Automatic
//! substeps cover both the part lattice and the pull (only the lattice with tiles).
//!
//! Pins hold particles, not parts: a pinned particle is kinematic, and with the bilinear
//! targets its part's centre is kept at its rest distance from the pin (a rod), so the
//! part swings about its pins instead of freezing as a rigid block. A part of one particle
//! is that particle, so its centre is pinned outright; with the seed's targets, or a
//! cloth one part across, a pin fixes its part, as in the thesis (see `Patches::new`).

use crate::solver::parallel::{self, CHUNK};
use bevy::math::{Affine3A, Vec3};

use crate::error::ClothError;
use crate::params::{ClothParams, Model, PatchParams, PatchTargets, Substeps};
use crate::solver::{ClothSolver, Layout, topology};

/// A pin's hold on its part: the part's centre stays `length` from the pin.
#[derive(Clone, Copy, Debug)]
struct Anchor {
    /// The part lattice node.
    part: u32,
    /// Index into the cloth's pin list.
    pin: u32,
    /// Rest distance from the pinned particle to the part's centre.
    length: f32,
    /// The distance at a switch into this model, faded to `length` with the targets'
    /// offsets (a hanging cloth's top parts hang up to 5% farther than rest).
    adopted: f32,
}

/// One part: a block of the particle grid.
#[derive(Clone, Copy, Debug)]
struct Part {
    i0: u32,
    j0: u32,
    width: u32,
    height: u32,
}

/// The part lattice and the particles' targets.
#[derive(Clone, Debug)]
pub struct Patches {
    /// The part centres as a mass-spring cloth.
    pub parts: Box<ClothSolver>,
    part_grid: (u32, u32),
    layout: Vec<Part>,
    grid: (u32, u32),
    /// Target of every particle (after the last `compute_targets`).
    pub targets: Vec<Vec3>,
    /// Weight of the centre correction per particle: 1 at the part's centre, falling off
    /// with rest distance from it.
    correction_weight: Vec<f32>,
    /// True for particles that are a part of their own (1×1 parts).
    single: Vec<bool>,
    /// Bilinear stencil per particle: the four centres (x0y0, x1y0, x0y1, x1y1) and the
    /// weights along x and y (outside [0, 1] beyond the outer centres).
    stencil: Vec<([u32; 4], f32, f32)>,
    /// Velocity of every particle's target over the last substep, `(t' − t)/h`: the pull's
    /// damping acts on the particle's velocity relative to it.
    pub target_velocity: Vec<Vec3>,
    /// The targets before the last `compute_targets` of a substep (for `target_velocity`).
    previous_targets: Vec<Vec3>,
    /// Rods from pins to the centres of their parts (parts larger than one particle).
    anchors: Vec<Anchor>,
    /// Rest distance between neighbouring particles along x and y (the length of the
    /// per-particle step of a cloth one part across).
    rest_step: (f32, f32),
    /// `(part_width, part_height, targets)` these were built for (the targets decide how
    /// pins hold the lattice).
    pub(in crate::solver) built_for: (u32, u32, PatchTargets),
    /// After a switch into this model: each particle's offset from its target at the
    /// switch, faded out over [`EASE_TIME`] (see [`Patches::adopt_state`]).
    ease: Vec<Vec3>,
    /// Seconds of the fade left (0: no offset).
    ease_left: f32,
}

/// Seconds over which a cloth switched into the patch model goes from its own shape to
/// the targets' (level of detail: a settled curtain's particles sit up to 8 mm off the
/// bilinear shape of 8×8 parts, and the pull closed that in one step).
pub const EASE_TIME: f32 = 0.5;

/// The share of the switch offset left when `left` of [`EASE_TIME`] remains: smoothstep,
/// so the targets start and end the fade at rest relative to the parts.
pub(in crate::solver) fn ease_share(left: f32) -> f32 {
    let s = (left / EASE_TIME).clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// A grid cut into parts of `part_size` particles (smaller at a non-dividing edge), row
/// by row: each part's rest centre, mass in particles, and its particles' centre
/// correction weights.
struct PartSplit {
    parts: Vec<Part>,
    centres: Vec<Vec3>,
    lumps: Vec<f32>,
    correction_weight: Vec<f32>,
    single: Vec<bool>,
}

impl PartSplit {
    fn new(local_rest: &[Vec3], (w, h): (u32, u32), (pw, ph): (u32, u32)) -> Self {
        let (nx, ny) = (w.div_ceil(pw), h.div_ceil(ph));
        let count = (nx * ny) as usize;
        let mut split = PartSplit {
            parts: Vec::with_capacity(count),
            centres: Vec::with_capacity(count),
            lumps: Vec::with_capacity(count),
            correction_weight: vec![1.0; local_rest.len()],
            single: vec![false; local_rest.len()],
        };
        let spacing = local_rest[0].distance(local_rest[1]);
        for py in 0..ny {
            for px in 0..nx {
                let part = Part {
                    i0: px * pw,
                    j0: py * ph,
                    width: pw.min(w - px * pw),
                    height: ph.min(h - py * ph),
                };
                let members: Vec<usize> = part_particles(&part, w).collect();
                let centre =
                    members.iter().map(|&k| local_rest[k]).sum::<Vec3>() / members.len() as f32;
                let reach = members
                    .iter()
                    .map(|&k| local_rest[k].distance(centre))
                    .fold(0.0, f32::max);
                for &k in &members {
                    split.correction_weight[k] =
                        1.0 - local_rest[k].distance(centre) / (reach + spacing);
                    split.single[k] = members.len() == 1;
                }
                split.centres.push(centre);
                split.lumps.push(members.len() as f32);
                split.parts.push(part);
            }
        }
        split
    }

    /// How each pin holds its part: the parts fixed outright (sorted, once each) and the
    /// rods from pins to part centres (see [`Patches::new`]).
    fn hold_pins(
        &self,
        pins: &[u32],
        local_rest: &[Vec3],
        (w, _): (u32, u32),
        (pw, ph): (u32, u32),
        bilinear: bool,
    ) -> (Vec<u32>, Vec<Anchor>) {
        let mut pinned_parts = Vec::new();
        let mut anchors = Vec::new();
        for (slot, &k) in pins.iter().enumerate() {
            let part = part_index(k, w, (pw, ph));
            if self.lumps[part as usize] == 1.0 || !bilinear {
                pinned_parts.push(part);
            } else {
                anchors.push(Anchor {
                    part,
                    pin: slot as u32,
                    length: local_rest[k as usize].distance(self.centres[part as usize]),
                    adopted: 0.0, // the fade's start, set by a switch (`adopt_state`)
                });
            }
        }
        pinned_parts.sort_unstable();
        pinned_parts.dedup();
        (pinned_parts, anchors)
    }
}

/// The point of the centres `c` at a particle's bilinear stencil (see [`bilinear_stencil`]).
#[inline]
fn bilinear_at(c: &[Vec3], &([a, b, d, e], s, t): &([u32; 4], f32, f32)) -> Vec3 {
    let [a, b, d, e] = [a, b, d, e].map(|k| c[k as usize]);
    (a * (1.0 - s) + b * s) * (1.0 - t) + (d * (1.0 - s) + e * s) * t
}

/// Per particle of a `w×h` grid cut into parts of `part_size`: the four part centres
/// around it (in lattice indices) and its bilinear coordinates `(s, t)` between them,
/// from the centres' rest coordinates along each axis (extrapolated past the outer ones).
fn bilinear_stencil((w, h): (u32, u32), (pw, ph): (u32, u32)) -> Vec<([u32; 4], f32, f32)> {
    let (nx, ny) = (w.div_ceil(pw), h.div_ceil(ph));
    // Rest coordinates of the centres along each axis, in particle indices.
    let column_centre: Vec<f32> = (0..nx)
        .map(|px| (px * pw) as f32 + (pw.min(w - px * pw) - 1) as f32 * 0.5)
        .collect();
    let row_centre: Vec<f32> = (0..ny)
        .map(|py| (py * ph) as f32 + (ph.min(h - py * ph) - 1) as f32 * 0.5)
        .collect();
    let bracket = |centres: &[f32], u: f32| -> (u32, u32, f32) {
        if centres.len() == 1 {
            return (0, 0, 0.0);
        }
        let last = centres.len() - 1;
        let a = centres
            .iter()
            .rposition(|&c| c <= u)
            .unwrap_or(0)
            .min(last - 1);
        (
            a as u32,
            a as u32 + 1,
            (u - centres[a]) / (centres[a + 1] - centres[a]),
        )
    };
    (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| {
            let (x0, x1, s) = bracket(&column_centre, i as f32);
            let (y0, y1, t) = bracket(&row_centre, j as f32);
            (
                [y0 * nx + x0, y0 * nx + x1, y1 * nx + x0, y1 * nx + x1],
                s,
                t,
            )
        })
        .collect()
}

/// The part lattice's own parameters: the cloth's springs, integrator, strain limit and
/// tearing, with the part damping added to the drag.
fn lattice_params(params: &ClothParams, patch: &PatchParams, substeps: u32) -> ClothParams {
    ClothParams {
        model: Model::MassSpring,
        drag: params.drag + patch.part_damping,
        substeps: Substeps::Fixed(substeps.max(1)),
        ..*params
    }
}

impl Patches {
    /// Splits a `grid` whose particles rest at `local_rest` into parts of `patch`'s size;
    /// a part holding a pinned particle has its centre pinned.
    pub fn new(
        local_rest: &[Vec3],
        grid: (u32, u32),
        pins: &[u32],
        params: &ClothParams,
        patch: &PatchParams,
        frame: Affine3A,
    ) -> Result<Self, ClothError> {
        let (w, h) = grid;
        let part_size = (patch.part_width.min(w), patch.part_height.min(h));
        let (nx, ny) = (w.div_ceil(part_size.0), h.div_ceil(part_size.1));
        let split = PartSplit::new(local_rest, grid, part_size);
        let stencil = bilinear_stencil(grid, part_size);
        // A part of one particle is that particle: pinned outright. With the bilinear
        // targets a larger part is held at its rest distance from each of its pins (see
        // the module doc). The seed's targets, and a cloth one part across, take the
        // part's orientation from its neighbours alone, so a part swinging on a rod would
        // carry its pinned particle's target off the pin (a 16×8 curtain of 8×8 parts
        // passed 100% strain at its pins): there a pin fixes its part, as in the thesis.
        let bilinear = patch.targets == PatchTargets::Bilinear && nx > 1 && ny > 1;
        let (pinned_parts, anchors) = split.hold_pins(pins, local_rest, grid, part_size, bilinear);
        let lattice = Layout {
            positions: split.centres,
            springs: topology::grid_spring_pairs(nx, ny),
            grid: Some((nx, ny)),
            ..Layout::default()
        };
        let mut parts = ClothSolver::new(
            lattice,
            &pinned_parts,
            &lattice_params(params, patch, 1),
            frame,
        )?;
        parts.particles.represents = split.lumps;
        scale_for_aspect(&mut parts.structure.springs, nx, part_size);
        parts.reset();
        let targets: Vec<Vec3> = local_rest
            .iter()
            .map(|x| frame.transform_point3(*x))
            .collect();
        Ok(Patches {
            parts: Box::new(parts),
            part_grid: (nx, ny),
            layout: split.parts,
            grid,
            target_velocity: vec![Vec3::ZERO; targets.len()],
            previous_targets: targets.clone(),
            targets,
            correction_weight: split.correction_weight,
            single: split.single,
            stencil,
            anchors,
            rest_step: rest_steps(local_rest, w as usize),
            built_for: patch.lattice_key(),
            ease: Vec::new(),
            ease_left: 0.0,
        })
    }

    /// Puts each part centre at the centre of mass of its particles' current state
    /// (position, previous position, velocity), so switching models mid-motion keeps the
    /// cloth where it is. `h`: the particles' last substep, the time between their
    /// previous and current positions — Verlet's implicit velocity; the lattice rescales
    /// it to its own substep in its next step (a switch from 5 to 10 substeps had doubled
    /// the lattice's velocity: the switch step moved a curtain twice a normal step).
    ///
    /// When `ease` (a switch from a running cloth, not a cloth built at rest), the
    /// targets then start at the particles' own shape and reach the model's over
    /// [`EASE_TIME`], so the pull does not snap the particles into it in one step; so do
    /// the pins' rods.
    pub fn adopt_state(
        &mut self,
        particles: &crate::solver::Particles,
        pins: &[u32],
        h: f32,
        patch: &PatchParams,
        ease: bool,
    ) {
        self.parts.clock.last_h = h;
        let w = self.grid.0;
        let parts = &mut self.parts.particles;
        for (k, part) in self.layout.iter().enumerate() {
            if parts.inv_mass[k] == 0.0 {
                continue; // pinned centres stay with their pins
            }
            let n = (part.width * part.height) as f32;
            let mean = |v: &[Vec3]| part_particles(part, w).map(|q| v[q]).sum::<Vec3>() / n;
            parts.position[k] = mean(&particles.position);
            parts.previous[k] = mean(&particles.previous);
            parts.velocity[k] = mean(&particles.velocity);
        }
        // Until the targets have moved once, each particle moves with its target.
        self.target_velocity.copy_from_slice(&particles.velocity);
        self.ease_left = 0.0;
        self.compute_targets(&particles.position, patch);
        if !ease {
            return;
        }
        self.ease = particles
            .position
            .iter()
            .zip(&self.targets)
            .map(|(x, t)| *x - *t)
            .collect();
        for anchor in &mut self.anchors {
            let pin = particles.position[pins[anchor.pin as usize] as usize];
            anchor.adopted = pin.distance(self.parts.particles.position[anchor.part as usize]);
        }
        self.ease_left = EASE_TIME;
        self.add_ease();
    }

    /// Adds the switch offset's share left to the targets.
    fn add_ease(&mut self) {
        if self.ease_left <= 0.0 {
            return;
        }
        let share = ease_share(self.ease_left);
        for (target, offset) in self.targets.iter_mut().zip(&self.ease) {
            *target += *offset * share;
        }
    }

    /// Recomputes the targets after a substep of `h` and their velocities `(t' − t)/h`.
    /// Allocates nothing.
    pub fn advance_targets(&mut self, x: &[Vec3], patch: &PatchParams, h: f32) {
        let inv_h = 1.0 / h;
        self.ease_left = (self.ease_left - h).max(0.0);
        if self.bilinear(patch) && self.ease_left <= 0.0 {
            // One pass: each new target and its velocity together.
            let c = &self.parts.particles.position;
            let pieces = self
                .targets
                .chunks_mut(CHUNK)
                .zip(self.target_velocity.chunks_mut(CHUNK))
                .zip(self.stencil.chunks(CHUNK));
            parallel::for_each(x.len(), pieces, |((targets, velocities), stencils)| {
                for ((target, v), stencil) in targets.iter_mut().zip(velocities).zip(stencils) {
                    let new = bilinear_at(c, stencil);
                    *v = (new - *target) * inv_h;
                    *target = new;
                }
            });
            return;
        }
        self.previous_targets.copy_from_slice(&self.targets);
        self.compute_targets(x, patch);
        for ((v, t), t0) in self
            .target_velocity
            .iter_mut()
            .zip(&self.targets)
            .zip(&self.previous_targets)
        {
            *v = (*t - *t0) * inv_h;
        }
    }

    /// Keeps each pinned part's centre at its rest distance from its pins (`pin_at(k)`:
    /// where pin `k` is now), moving it along the rod and changing its velocity by the
    /// same over `h`. Gauss–Seidel over the anchors, a few sweeps (a part with a row of
    /// pins hangs from all of them).
    pub fn hold_parts(&mut self, pin_at: impl Fn(usize) -> Vec3, h: f32) {
        const SWEEPS: usize = 4;
        let p = &mut self.parts.particles;
        let share = ease_share(self.ease_left);
        for _ in 0..SWEEPS {
            for anchor in &self.anchors {
                let k = anchor.part as usize;
                let pin = pin_at(anchor.pin as usize);
                let d = p.position[k] - pin;
                let len = d.length();
                let length = anchor.length + (anchor.adopted - anchor.length) * share;
                let goal = if len > f32::EPSILON {
                    pin + d * (length / len)
                } else {
                    pin
                };
                let delta = goal - p.position[k];
                p.position[k] = goal;
                p.velocity[k] += delta / h;
            }
        }
    }

    /// `value(i)` summed over each part's particles, per part.
    pub fn part_sums(&self, value: impl Fn(usize) -> Vec3) -> Vec<Vec3> {
        let w = self.grid.0;
        self.layout
            .iter()
            .map(|part| part_particles(part, w).map(&value).sum())
            .collect()
    }

    /// The part holding particle `i`.
    pub fn part_of(&self, i: u32) -> usize {
        let first = self.layout[0];
        part_index(i, self.grid.0, (first.width, first.height)) as usize
    }

    /// Updates the lattice's parameters (springs, drag, integrator, tearing) and substeps.
    pub fn set_params(&mut self, params: &ClothParams, patch: &PatchParams, substeps: u32) {
        // Validated with the cloth's parameters already; the lattice's differ only in
        // model, drag (+ a validated damping) and substeps.
        self.parts
            .apply_params(&lattice_params(params, patch, substeps));
    }

    /// True when particle `i` is a part of its own (its position is its part's centre).
    pub fn is_single(&self, i: usize) -> bool {
        self.single[i]
    }

    /// Computes and caches the lattice's stable substeps for `dt` if its parameters or
    /// `dt` changed since the last time.
    pub fn refresh_lattice_substeps(&mut self, dt: f32) {
        self.parts.refresh_substep_cache(dt);
    }

    /// Stable substeps of the part lattice for a step of `dt`: the cached value when it
    /// is current, otherwise computed now.
    pub fn lattice_substeps(&self, dt: f32) -> u32 {
        self.parts.cached_substeps(dt)
    }

    /// Number of parts.
    pub fn part_count(&self) -> usize {
        self.layout.len()
    }

    /// Targets of every particle from the part centres (Sladović 2014 §3.4, fig. 7–9), given
    /// the particles' current positions `x` (used only when the cloth is one part wide or
    /// high). Allocates nothing.
    pub fn compute_targets(&mut self, x: &[Vec3], patch: &PatchParams) {
        if self.bilinear(patch) {
            let c = &self.parts.particles.position;
            for (target, stencil) in self.targets.iter_mut().zip(&self.stencil) {
                *target = bilinear_at(c, stencil);
            }
        } else {
            let (nx, ny) = self.part_grid;
            for py in 0..ny {
                for px in 0..nx {
                    self.place_part_targets(px, py, x, patch);
                }
            }
        }
        self.add_ease();
    }

    /// The seed's targets (§3.4 pseudocode) of the particles of part `(px, py)`.
    fn place_part_targets(&mut self, px: u32, py: u32, x: &[Vec3], patch: &PatchParams) {
        let (nx, ny) = self.part_grid;
        let w = self.grid.0;
        let centres = &self.parts.particles.position;
        let k = (py * nx + px) as usize;
        let part = self.layout[k];
        let c = centres[k];
        if part.width == 1 && part.height == 1 {
            // A part of one particle is that particle: the model is mass-spring.
            self.targets[(part.j0 * w + part.i0) as usize] = c;
            return;
        }
        let size = |p: Part, horizontal: bool| if horizontal { p.width } else { p.height } as f32;
        // Neighbour centres and their rest distances in particle spacings; a missing
        // neighbour is a "ghost" mirrored through this centre (fig. 9).
        let neighbour = |dx: i32, dy: i32| -> Option<(Vec3, f32)> {
            let (qx, qy) = (px as i32 + dx, py as i32 + dy);
            if qx < 0 || qy < 0 || qx >= nx as i32 || qy >= ny as i32 {
                return None;
            }
            let q = (qy as u32 * nx + qx as u32) as usize;
            let horizontal = dx != 0;
            Some((
                centres[q],
                0.5 * (size(part, horizontal) + size(self.layout[q], horizontal)),
            ))
        };
        let axis = |minus: Option<(Vec3, f32)>, plus: Option<(Vec3, f32)>, horizontal: bool| match (
            minus, plus,
        ) {
            (Some(m), Some(p)) => (m, p),
            (Some((m, d)), None) => ((m, d), (2.0 * c - m, d)),
            (None, Some((p, d))) => ((2.0 * c - p, d), (p, d)),
            // One part across: measure the direction from the part's own particles.
            // Its length is the rest spacing, so the pull restores the cloth's
            // extent along that axis (a measured length would give no stiffness).
            (None, None) => {
                let rest = self.rest_along(horizontal);
                let step = own_step(&part, x, w, horizontal).normalize_or_zero() * rest;
                let n = size(part, horizontal);
                ((c - step * n, n), (c + step * n, n))
            }
        };
        let ((l, dl), (r, dr)) = axis(neighbour(-1, 0), neighbour(1, 0), true);
        let ((t, dt), (b, db)) = axis(neighbour(0, -1), neighbour(0, 1), false);
        // Sladović 2014's pseudocode, generalised to unequal neighbours (edge parts):
        // horizontal = (right − left) / (2w), vertical = (bottom − top) / (2h),
        // start = (top + left)/2 shifted by half a step; target = start + j·v + i·h.
        let horizontal = (r - l) / (dl + dr);
        let vertical = (b - t) / (dt + db);
        let start = 0.5 * (t + l)
            + horizontal * (0.5 * (dl - part.width as f32 + 1.0))
            + vertical * (0.5 * (dt - part.height as f32 + 1.0));
        self.fill_targets(&part, start, horizontal, vertical);
        if patch.center_correction {
            self.correct_centre(part, c);
        }
    }

    /// The rest spacing of the particles along a row (`horizontal`) or down a column.
    fn rest_along(&self, horizontal: bool) -> f32 {
        if horizontal {
            self.rest_step.0
        } else {
            self.rest_step.1
        }
    }

    /// Puts the targets of `part`'s particles on the lattice `start + j·vertical +
    /// i·horizontal`.
    fn fill_targets(&mut self, part: &Part, start: Vec3, horizontal: Vec3, vertical: Vec3) {
        let w = self.grid.0;
        for j in 0..part.height {
            for i in 0..part.width {
                let index = ((part.j0 + j) * w + part.i0 + i) as usize;
                self.targets[index] = start + horizontal * i as f32 + vertical * j as f32;
            }
        }
    }

    /// The thesis's proposed correction: move the targets' centre of mass onto the part's
    /// centre `c`, fully at the centre, less toward the edges.
    fn correct_centre(&mut self, part: Part, c: Vec3) {
        let w = self.grid.0;
        let count = (part.width * part.height) as f32;
        let mean = part_particles(&part, w)
            .map(|q| self.targets[q])
            .sum::<Vec3>()
            / count;
        let offset = c - mean;
        for q in part_particles(&part, w) {
            self.targets[q] += offset * self.correction_weight[q];
        }
    }

    /// True when the targets are the bilinear ones (a cloth one part across uses the
    /// seed's).
    fn bilinear(&self, patch: &PatchParams) -> bool {
        let (nx, ny) = self.part_grid;
        patch.targets == PatchTargets::Bilinear && nx > 1 && ny > 1
    }

    /// Springs of the part lattice torn so far.
    pub fn torn_count(&self) -> usize {
        self.parts.torn_count()
    }

    /// Acting springs of the part lattice.
    pub fn spring_count(&self) -> usize {
        self.parts.spring_count()
    }
}

/// Scales the part lattice's springs for parts of `pw × ph` particles: a horizontal
/// spring stands for `ph` rows of particle springs in parallel, each `pw` springs in
/// series, so its stiffness is `k·ph/pw` (vertical: `k·pw/ph`). A diagonal spring spans
/// `(pw, ph)`; its share along each axis is weighed the same way, `2·pw·ph/(pw² + ph²)`.
/// Square parts keep the particle constants.
fn scale_for_aspect(springs: &mut topology::Springs, nx: u32, (pw, ph): (u32, u32)) {
    if pw == ph {
        springs.stiffness_scale = None;
        return;
    }
    let (w, h) = (pw as f32, ph as f32);
    let (horizontal, vertical, diagonal) = (h / w, w / h, 2.0 * w * h / (w * w + h * h));
    let scale = (0..springs.len())
        .map(|s| {
            let (a, b) = (springs.a[s], springs.b[s]);
            if a / nx == b / nx {
                horizontal
            } else if a % nx == b % nx {
                vertical
            } else {
                diagonal
            }
        })
        .collect();
    springs.stiffness_scale = Some(scale);
}

/// The part (lattice index) holding particle `k` of a grid `w` wide cut into parts of
/// `pw × ph` (row by row, smaller parts at a non-dividing edge).
fn part_index(k: u32, w: u32, (pw, ph): (u32, u32)) -> u32 {
    (k / w / ph) * w.div_ceil(pw) + (k % w) / pw
}

fn part_particles(part: &Part, w: u32) -> impl Iterator<Item = usize> + '_ {
    let p = *part;
    (p.j0..p.j0 + p.height)
        .flat_map(move |j| (p.i0..p.i0 + p.width).map(move |i| (j * w + i) as usize))
}

/// For a cloth one part across: the step between neighbouring particle columns (or rows)
/// of the part, from the mean positions of its first and last column (row).
fn own_step(part: &Part, x: &[Vec3], w: u32, horizontal: bool) -> Vec3 {
    let n = if horizontal { part.width } else { part.height };
    if n < 2 {
        return Vec3::ZERO;
    }
    let line_mean = |k: u32| {
        let (count, sum) = if horizontal {
            (
                part.height,
                (0..part.height)
                    .map(|j| x[((part.j0 + j) * w + part.i0 + k) as usize])
                    .sum::<Vec3>(),
            )
        } else {
            (
                part.width,
                (0..part.width)
                    .map(|i| x[((part.j0 + k) * w + part.i0 + i) as usize])
                    .sum::<Vec3>(),
            )
        };
        sum / count as f32
    };
    (line_mean(n - 1) - line_mean(0)) / (n - 1) as f32
}

/// The rest distance from particle 0 to its neighbour along a row and down a column (0
/// where there is none).
fn rest_steps(local_rest: &[Vec3], width: usize) -> (f32, f32) {
    let step = |b: usize| local_rest.get(b).map_or(0.0, |x| x.distance(local_rest[0]));
    (step(1), step(width))
}
