//! A frame budget shared among cloths: the work (particles × substeps) all cloths may
//! do in one step, given out as a cap on each cloth's substeps. Game engines bound cloth
//! by time, not by accuracy (NvCloth and Chaos Cloth run a fixed count of iterations a
//! frame, Magica Cloth 2 a fixed frequency with a cap on updates a frame); here the
//! accuracy loop keeps choosing the substeps, inside the share it is given.
//!
//! The share is a plain function of the cloths' claims, so it gives the same caps on any
//! machine and thread count: a budget of time becomes one of work through a planned cost
//! per particle-substep.

/// One cloth's claim on a shared budget.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BudgetClaim {
    /// Its particles: the work of one of its substeps.
    pub particles: usize,
    /// The substeps its last step needed ([`StepReport::needed`](super::StepReport::needed);
    /// 0 before its first step).
    pub needed: u32,
    /// Its weight when the budget is short (1: as any other; 2: twice the share).
    pub priority: f32,
    /// Whether the budget can cap it: XPBD at automatic substeps. The others (a fixed
    /// count, an explicit model's stable count) take what they need first.
    pub cappable: bool,
}

/// A cloth whose last step ended with a structural spring stretched past this is not
/// capped in its next step: the budget gives way before the cloth does (what gives is
/// accuracy, never stability). Half the 50% past which a cloth no longer looks like
/// itself.
pub const GIVE_WAY_STRAIN: f32 = 0.25;

impl BudgetClaim {
    /// The claim of `cloth` from its last step, at `priority`. A cloth whose last step
    /// ended past [`GIVE_WAY_STRAIN`] is not capped.
    pub fn of(cloth: &super::ClothSolver, priority: f32) -> Self {
        BudgetClaim {
            particles: cloth.particle_count(),
            needed: cloth.last_report().needed,
            priority,
            cappable: cloth.budget_caps() && !gives_way(cloth),
        }
    }
}

/// Whether the budget gives way to `cloth`: its last step ended past
/// [`GIVE_WAY_STRAIN`] (the step's own measure when it took one, XPBD's closed loop;
/// else measured now, a pass over the structural springs).
pub fn gives_way(cloth: &super::ClothSolver) -> bool {
    let strain = cloth
        .last_report()
        .max_strain
        .unwrap_or_else(|| cloth.strain().max);
    strain > GIVE_WAY_STRAIN
}

/// Shares `work` (particle-substeps a step) among `claims` and writes each cloth's cap
/// on its substeps to `caps` (`None` for a cloth the budget does not cap), in order.
///
/// The cloths that cannot be capped take their need first. When the rest need no more
/// than what is left, each is given its need and a share of the remainder by priority,
/// so a cloth whose need grows within a step has room. When they need more, the work
/// left is filled by priority (water-filling: a cloth needing less than its share takes
/// its need, and what it leaves goes to the others), and each cap is at least one
/// substep.
pub fn share_budget(claims: &[BudgetClaim], work: f64, caps: &mut Vec<Option<u32>>) {
    caps.clear();
    caps.resize(claims.len(), None);
    let fixed: f64 = claims.iter().filter(|c| !c.cappable).map(demand).sum();
    let left = (work - fixed).max(0.0);
    let wanted: f64 = claims.iter().filter(|c| c.cappable).map(demand).sum();
    let weights: f64 = claims.iter().filter(|c| c.cappable).map(weight).sum();
    if wanted <= left {
        let spare = left - wanted;
        for (c, out) in claims
            .iter()
            .zip(caps.iter_mut())
            .filter(|(c, _)| c.cappable)
        {
            let extra = if weights > 0.0 {
                spare * weight(c) / weights
            } else {
                0.0
            };
            *out = cap(c, demand(c) + extra);
        }
        return;
    }
    // Water-filling: the cloths in order of need per unit of priority, each taking the
    // smaller of its need and its share of what is left.
    ORDER.with_borrow_mut(|order| water_fill(claims, order, caps, (left, weights)));
}

/// A claim's work: its particles times the substeps it needs.
fn demand(c: &BudgetClaim) -> f64 {
    c.particles.max(1) as f64 * f64::from(c.needed.max(1))
}

/// A claim's weight in the sharing: its priority (0 for a negative one).
fn weight(c: &BudgetClaim) -> f64 {
    f64::from(c.priority.max(0.0))
}

/// The substeps `share` of work buys a claim's particles, at least one.
fn cap(c: &BudgetClaim, share: f64) -> Option<u32> {
    let n = (share / c.particles.max(1) as f64).floor();
    Some(n.clamp(1.0, u32::MAX as f64) as u32)
}

thread_local! {
    /// [`share_budget`]'s order of the cloths it caps, kept so a step allocates nothing.
    static ORDER: std::cell::RefCell<Vec<usize>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Water-filling: the cappable cloths of `claims` in order of need per unit of priority
/// (sorted into `order`), each capped at the smaller of its need and its share of what
/// is `left` (the work), shared by `weights` (their priorities' sum).
fn water_fill(
    claims: &[BudgetClaim],
    order: &mut Vec<usize>,
    caps: &mut [Option<u32>],
    (mut left, mut weights): (f64, f64),
) {
    order.clear();
    order.extend((0..claims.len()).filter(|&i| claims[i].cappable));
    let per_weight = |i: &usize| {
        let c = &claims[*i];
        let w = weight(c);
        if w > 0.0 {
            demand(c) / w
        } else {
            f64::INFINITY
        }
    };
    order.sort_by(|a, b| per_weight(a).total_cmp(&per_weight(b)).then(a.cmp(b)));
    for &i in order.iter() {
        let c = &claims[i];
        let share = if weights > 0.0 {
            left * weight(c) / weights
        } else {
            0.0
        };
        let given = share.min(demand(c));
        caps[i] = cap(c, given);
        left -= given;
        weights -= weight(c);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn claim(particles: usize, needed: u32, priority: f32) -> BudgetClaim {
        BudgetClaim {
            particles,
            needed,
            priority,
            cappable: true,
        }
    }

    #[test]
    fn enough_work_gives_each_its_need_and_the_rest_by_priority() {
        let claims = [claim(100, 10, 1.0), claim(100, 20, 3.0)];
        let mut caps = Vec::new();
        // Needs 1,000 + 2,000; 4,000 of spare: 1,000 and 3,000 more.
        share_budget(&claims, 7_000.0, &mut caps);
        assert_eq!(caps, [Some(20), Some(50)]);
    }

    #[test]
    fn short_work_is_filled_by_priority_and_a_small_need_leaves_its_rest() {
        // 3,000 for needs of 500, 4,000 and 4,000: the small one takes 500, the others
        // 1,250 each.
        let claims = [claim(100, 5, 1.0), claim(100, 40, 1.0), claim(100, 40, 1.0)];
        let mut caps = Vec::new();
        share_budget(&claims, 3_000.0, &mut caps);
        assert_eq!(caps, [Some(5), Some(12), Some(12)]);
        // Twice the priority, twice the share.
        let claims = [claim(100, 40, 2.0), claim(100, 40, 1.0)];
        share_budget(&claims, 3_000.0, &mut caps);
        assert_eq!(caps, [Some(20), Some(10)]);
    }

    #[test]
    fn what_cannot_be_capped_is_taken_first_and_a_cap_is_never_zero() {
        let mut fixed = claim(1_000, 8, 1.0);
        fixed.cappable = false;
        let claims = [fixed, claim(100, 30, 1.0)];
        let mut caps = Vec::new();
        share_budget(&claims, 9_000.0, &mut caps);
        assert_eq!(caps, [None, Some(10)]);
        share_budget(&claims, 1_000.0, &mut caps);
        assert_eq!(caps, [None, Some(1)]);
        share_budget(&[claim(100, 30, 0.0)], 1_000.0, &mut caps);
        assert_eq!(caps, [Some(1)]);
    }
}
