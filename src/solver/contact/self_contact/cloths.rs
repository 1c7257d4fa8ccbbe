//! Cloth–cloth contact: each cloth keeps a copy of the other cloths' particles near it
//! (see the self-collision module's doc).

use bevy::math::Vec3;

use crate::solver::ClothSolver;

/// A particle of another cloth, as it was when the step began.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Other {
    pub(super) x: Vec3,
    pub(super) v: Vec3,
    pub(super) w: f32,
    /// Where it comes from: its cloth's place among those given to [`collide_cloths`],
    /// and its index there ([`exchange_cloths`] reads it again).
    pub(super) cloth: u32,
    pub(super) particle: u32,
}

/// The box around `x`.
pub(super) fn bounds(x: &[Vec3]) -> (Vec3, Vec3) {
    x.iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        })
}

/// Cloth–cloth contact for the step about to begin (see the module doc): each cloth of
/// `cloths` with self-collision on takes the particles of the others with it on that
/// lie within its box grown by a margin (their positions and velocities now, and their
/// inverse masses: 0 for a cloth that will not step, `moving` false, such as a sleeping
/// one, so the cloth that steps takes the whole correction). Call it before the cloths'
/// `begin_step`; a cloth keeps its copy until the next call.
pub fn collide_cloths(cloths: &mut [(&mut ClothSolver, bool)]) {
    let on: Vec<bool> = cloths
        .iter()
        .map(|(c, _)| c.params.self_collision.enabled)
        .collect();
    let boxes: Vec<(Vec3, Vec3)> = cloths
        .iter()
        .map(|(c, _)| bounds(&c.particles.position))
        .collect();
    for a in 0..cloths.len() {
        cloths[a].0.self_contact.tag = Some(a as u32);
        let mut others = std::mem::take(&mut cloths[a].0.self_contact.others);
        others.clear();
        if on[a] {
            // What can come within reach of the cloth in a step: four spacings, and where
            // a particle's speed takes it in 50 ms (three 16 ms steps).
            let (lo, hi) = boxes[a];
            let margin = 4.0 * cloths[a].0.self_contact.spacing.max(0.01);
            for b in (0..cloths.len()).filter(|&b| b != a && on[b]) {
                let (other, moving) = (&*cloths[b].0, cloths[b].1);
                let p = &other.particles;
                for i in 0..p.len() {
                    let reach = margin + p.velocity[i].length() * 0.05;
                    let x = p.position[i];
                    if x.cmpge(lo - reach).all() && x.cmple(hi + reach).all() {
                        others.push(Other {
                            x,
                            v: p.velocity[i],
                            w: if moving { p.inv_mass[i] } else { 0.0 },
                            cloth: b as u32,
                            particle: i as u32,
                        });
                    }
                }
            }
        }
        cloths[a].0.self_contact.others = others;
    }
}

/// Refreshes every cloth's copy of the other cloths' particles ([`collide_cloths`]) to
/// where those are now, for cloths stepped stage by stage together: each substep's
/// cloth–cloth contact then keeps apart from where the others were one substep ago, not
/// one step ago. `cloths` may be any of those given to [`collide_cloths`], in any order;
/// a copy of a cloth not among them stays as it was.
pub fn exchange_cloths(cloths: &mut [&mut ClothSolver]) {
    for a in 0..cloths.len() {
        refresh(cloths, a);
    }
}

/// Cloth `a`'s copy of the others' particles, refreshed from those of `cloths` (matched
/// by the place [`collide_cloths`] gave each).
pub(in crate::solver) fn refresh(cloths: &mut [&mut ClothSolver], a: usize) {
    let mut others = std::mem::take(&mut cloths[a].self_contact.others);
    let mut from: Option<(u32, usize)> = None; // the last source found (they come in runs)
    for o in &mut others {
        let found = match from {
            Some((tag, b)) if tag == o.cloth => Some(b),
            _ => cloths
                .iter()
                .position(|c| c.self_contact.tag == Some(o.cloth)),
        };
        let Some(b) = found else { continue };
        from = Some((o.cloth, b));
        if let Some(&x) = cloths[b].particles.position.get(o.particle as usize) {
            o.x = x;
        }
    }
    cloths[a].self_contact.others = others;
}
