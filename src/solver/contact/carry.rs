//! The cloth carried along with the particles moved out of an overlap they started in
//! (spawned through a body, a collider that jumped). Such a move is pre-stabilised: the
//! particle's `previous` moves with it, so it adds no velocity (Macklin et al. 2014 §5.2
//! do this for the contacts alone). But its neighbours then see a stretched spring, and
//! the model's constraints pull them after it as motion; a particle on the surface tied
//! to one still inside is pulled in and pushed out every substep, and what each pull has
//! along the surface builds up: the push became a launch, the cloth's free edges whipping
//! out at twice the cap and more. So the whole cloth is pre-stabilised with it.

use bevy::math::Vec3;

use super::{Contact, EDGES};
use crate::solver::state::mark;
use crate::solver::{Particles, Springs};

/// Gauss–Seidel passes over the springs: each carries the push a few springs farther,
/// and what is left the model's constraints take up as motion. A 16 × 16 cloth hung
/// through a ball moves at most 0.82 of the cap with 16 passes; with 8 it overshot the
/// cap by 11% (mass-spring).
pub(in crate::solver) const CARRY_PASSES: usize = 16;

/// How deep, in the cloth's longest edges, an overlap must appear at once for the cloth
/// to be carried out with it: a quarter of an edge is far past anything a projection
/// after contact leaves, and a fraction of any overlap a spawn or a jump makes.
const DEEP_OVERLAP: f32 = 0.25;

/// The overlaps a substep lifted particles out of, and the carry's own state (its
/// storage kept, so a step allocates nothing once it has grown).
#[derive(Clone, Debug, Default)]
pub(crate) struct Carry {
    /// The particles this substep moved out of an overlap they started in, and by how
    /// much.
    lifted: Vec<(u32, Vec3)>,
    /// Each particle's overlap left at the end of the last substep (what its lift did not
    /// undo), m.
    left_inside: Vec<f32>,
    /// The most any particle's overlap grew since the last substep left it, m: an overlap
    /// that appears at once (a spawn through a body, a collider that jumped), not one
    /// pressed in over many substeps.
    newest_overlap: f32,
    /// Each particle's move this substep by the lift and the carry.
    moved: Vec<Vec3>,
    /// Whether a deep overlap is coming out (some particle has been lifted in every
    /// substep since one appeared that deep).
    carrying: bool,
}

/// The lift below which a particle counts as resting on the surface rather than started
/// inside: this fraction of the substep's cap on the lift (float noise in the push less the
/// particle's own approach).
const LIFT_NOISE: f32 = 0.01;

impl Carry {
    /// Starts a substep's contact over `n` particles.
    pub fn begin(&mut self, n: usize) {
        self.lifted.clear();
        self.newest_overlap = 0.0;
        self.left_inside.resize(n, 0.0);
    }

    /// Particle `i`'s overlap left by the last substep, forgotten (it is noted again if
    /// the particle is still in).
    #[inline]
    pub fn take_left(&mut self, i: usize) -> f32 {
        let left = self.left_inside[i];
        if left != 0.0 {
            self.left_inside[i] = 0.0;
        }
        left
    }

    /// Notes that particle `i`, `left` inside since the last substep, started this one
    /// `overlap` deep and was `lifted` out of it, at most `cap` (m) a substep.
    #[inline]
    pub fn note(&mut self, i: usize, left: f32, (lifted, overlap): (Vec3, f32), cap: f32) {
        self.newest_overlap = self.newest_overlap.max(overlap - left);
        self.left_inside[i] = (overlap - lifted.length()).max(0.0);
        // A lift of float noise (a particle resting on the surface) is none.
        if lifted.length_squared() > LIFT_NOISE * LIFT_NOISE * cap * cap {
            self.lifted.push((i as u32, lifted));
        }
    }
}

impl Contact {
    /// Carries the cloth along with the particles [`Contact::resolve`] lifted out of an
    /// overlap this substep: each structural and shear spring is brought back to its
    /// length before the lifts, over [`CARRY_PASSES`] Gauss–Seidel passes, its free ends
    /// moved by inverse mass (the lifted ones too, so two lifted different ways keep
    /// their spring), positions and `previous` alike: velocities are unchanged.
    ///
    /// Only while an overlap that appeared at once deeper than [`DEEP_OVERLAP`] of the
    /// cloth's `longest_edge` (m) comes out: from the substep it appears in until one that
    /// lifts nothing. Each particle it moves is marked in `touched`.
    pub fn carry(
        &mut self,
        p: &mut Particles,
        springs: &Springs,
        longest_edge: f32,
        touched: &mut [bool],
    ) {
        // An overlap shallower than that (a particle nudged into a crease of two
        // colliders, or into a thin pole by a projection after contact), or pressed in
        // over many substeps (the bottom of a stack), is contact's own business; one that
        // appears that deep at once is carried until its last particle is out.
        let c = &mut self.carry;
        if c.lifted.is_empty() {
            c.carrying = false;
            return;
        }
        c.carrying |= c.newest_overlap > DEEP_OVERLAP * longest_edge;
        if !c.carrying {
            return;
        }
        let moved = &mut c.moved;
        moved.clear();
        moved.resize(p.position.len(), Vec3::ZERO);
        for &(i, lift) in &c.lifted {
            moved[i as usize] = lift;
        }
        restore_lengths(p, springs, moved);
        for (i, m) in moved.iter().enumerate() {
            if p.inv_mass[i] > 0.0 && *m != Vec3::ZERO {
                mark(touched, i);
            }
        }
    }
}

/// Brings each structural and shear spring back to its length before `moved` (each
/// particle's move so far this substep, updated), by inverse mass, positions and
/// `previous` alike.
fn restore_lengths(p: &mut Particles, springs: &Springs, moved: &mut [Vec3]) {
    let edges = EDGES.map(|kind| springs.ranges[kind as usize].clone());
    for _ in 0..CARRY_PASSES {
        for s in edges.iter().flat_map(|r| r.clone()) {
            let (a, b) = (springs.a[s] as usize, springs.b[s] as usize);
            let (wa, wb) = (p.inv_mass[a], p.inv_mass[b]);
            // Ends moved alike keep their length (both unmoved: most of the cloth).
            if moved[a] == moved[b] || wa + wb == 0.0 || !springs.alive[s] {
                continue;
            }
            let (xa, xb) = (p.position[a], p.position[b]);
            let before = ((xa - moved[a]) - (xb - moved[b])).length();
            let d = xa - xb;
            let length = d.length();
            if length <= f32::MIN_POSITIVE {
                continue;
            }
            let correction = d * ((length - before) / (length * (wa + wb)));
            for (i, step) in [(a, -correction * wa), (b, correction * wb)] {
                p.position[i] += step;
                p.previous[i] += step;
                moved[i] += step;
            }
        }
    }
}
