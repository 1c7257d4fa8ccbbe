//! XPBD's step (Macklin, Müller and Chentanez 2016; small steps, Macklin et al. 2019,
//! algorithm 1): predict from the external forces, project every spring's constraint once
//! a substep (on a grid's stencil, `lattice/xpbd.rs`; otherwise `xpbd.rs`), a fabric's
//! bending hinges (`bending.rs`) as often as their stiffness asks, then the tethers to
//! the pins (Kim, Chentanez and Müller 2012, `tethers.rs`); velocities are the change
//! from the prediction over `h`.

use super::ModelSteps;
use crate::params::{Environment, XpbdParams, XpbdSolve};
use crate::solver::chains::Chains;
use crate::solver::clock::Clock;
use crate::solver::integrate::symplectic_euler;
use crate::solver::lattice::Stencil;
use crate::solver::{
    ClothSolver, ModelState, Particles, SpringKind, Springs, family_stiffness, xpbd,
};

impl ModelSteps for XpbdParams {
    /// A cloth's springs never change (they only tear): the constraints are built once
    /// per switch to XPBD.
    fn build(&self, cloth: &mut ClothSolver, _compute: bool) {
        if !matches!(cloth.model, ModelState::Xpbd(_)) {
            let n = cloth.particles.len();
            // A grid is projected on its stencil: no constraint lists.
            let general = cloth.structure.stencil.is_none();
            let springs = &cloth.structure.springs;
            let mut constraints = xpbd::Constraints::new(springs, n, general);
            // A grid's lines are its rows and columns on the stencil (`lattice/lines.rs`).
            if general {
                constraints.chains = Chains::new(springs, &cloth.structure.local_rest);
            }
            cloth.model = ModelState::Xpbd(Box::new(constraints));
        }
    }

    /// This step's seam lengths, torn springs and pins.
    fn prepare(&self, cloth: &mut ClothSolver, _dt: f32) {
        if let ModelState::Xpbd(constraints) = &mut cloth.model {
            if cloth.structure.stencil.is_none() {
                constraints.sync(&cloth.structure.springs);
            }
            if self.solve == XpbdSolve::Lines {
                constraints.chains.sync(&cloth.structure.springs);
            }
        }
        refresh_tethers(cloth, self);
    }

    /// How often this step projects the fabric's hinges
    /// (`ClothSolver::hinge_every`).
    fn begin(&self, cloth: &mut ClothSolver, dt: f32, _ratio: Option<f32>) {
        let every = cloth.hinge_every(dt);
        if let ModelState::Xpbd(constraints) = &mut cloth.model {
            constraints.hinge_every = every;
        }
    }

    /// Gravity, wind and drag only: the springs are constraints.
    fn forces(&self, cloth: &mut ClothSolver, env: &Environment) {
        cloth.external_forces(env);
    }

    /// The prediction `v += h f/m`, `x += h v`, whatever the integrator setting; with
    /// lines, the position's step compensated (`chains.rs`).
    fn integrate(&self, cloth: &mut ClothSolver) {
        let (p, h, drag) = (&mut cloth.particles, cloth.clock.h, cloth.params.drag);
        match self.solve {
            XpbdSolve::Lines => symplectic_euler::<true>(p, h, drag),
            XpbdSolve::Sweep => symplectic_euler::<false>(p, h, drag),
        }
    }

    /// Every spring's constraint projected once, the strain limit with the structural and
    /// shear ones, the fabric's hinges at their own rate, then the tethers, last so the
    /// bound they keep holds at the end of the substep.
    fn constrain(&self, cloth: &mut ClothSolver) {
        let ModelState::Xpbd(constraints) = &mut cloth.model else {
            return;
        };
        let h = cloth.clock.h;
        let families = families(&cloth.params, h);
        let (stencil, p) = (&mut cloth.structure.stencil, &mut cloth.particles);
        match self.solve {
            XpbdSolve::Sweep => sweep_families(stencil, constraints, p, &families, h),
            XpbdSolve::Lines => {
                let springs = &cloth.structure.springs;
                along_lines(stencil, constraints, (p, springs), &families, h);
            }
        }
        if let Some(fabric) = cloth.params.fabric {
            let group = hinge_group(constraints.hinge_every, &cloth.clock);
            if group > 0 {
                let hinges = &cloth.structure.hinges;
                hinges.project(&mut cloth.particles, fabric.bending, h, group);
            }
        }
        let pins = &cloth.drivers.pins;
        constraints.tethers.project(&mut cloth.particles, pins, h);
    }

    /// The strain limit along the lines once more ([`limit_at_end`]).
    fn settle(&self, cloth: &mut ClothSolver) {
        if self.solve == XpbdSolve::Lines {
            limit_at_end(cloth);
        }
    }

    fn end(&self, cloth: &mut ClothSolver) {
        cloth.tear_overstretched();
    }
}

/// Each family's constraint parameters for a substep of `h` (by [`SpringKind`]); the
/// strain limit on the structural and shear ones.
fn families(params: &crate::params::ClothParams, h: f32) -> [xpbd::Family; 5] {
    let (springs, limit) = (&params.springs_in_use(), params.strain_limit);
    SpringKind::ALL.map(|kind| {
        let k = family_stiffness(springs, kind);
        let limited = matches!(kind, SpringKind::Structural | SpringKind::Shear);
        xpbd::Family::new(k, springs.damping, h, limit.filter(|_| limited))
    })
}

/// The constraints with the structural family along its lines: the other families
/// swept, then the structural one along its lines (one Newton step of each line's
/// lengths), then the sweep [`after_lines`] asks for. On a grid's stencil all of it on
/// its lanes, loaded once and stored once.
fn along_lines(
    stencil: &mut Option<Stencil>,
    constraints: &mut xpbd::Constraints,
    (p, springs): (&mut Particles, &Springs),
    families: &[xpbd::Family; 5],
    h: f32,
) {
    let structural = SpringKind::Structural as usize;
    let mut before = *families;
    before[structural].on = false;
    before[SpringKind::Shear as usize].on &= !shear_after_lines(families);
    let f = families[structural];
    let Some(stencil) = stencil else {
        sweep_families(&mut None, constraints, p, &before, h);
        constraints.chains.solve(p, f, h);
        let (x, w) = (&p.position, &p.inv_mass);
        if let Some(limit) = limit_past(f, |max| {
            springs.any_longer_than(SpringKind::Structural, x, w, max)
        }) {
            constraints.chains.solve(p, limit, h);
        }
        sweep_families(&mut None, constraints, p, &after_lines(families), h);
        return;
    };
    stencil.begin_xpbd(p, families);
    stencil.sweep_xpbd(&p.inv_mass, &before);
    stencil.solve_lines(&p.inv_mass, f);
    let w = &p.inv_mass;
    if let Some(limit) = limit_past(f, |max| stencil.any_longer(SpringKind::Structural, w, max)) {
        stencil.solve_lines(w, limit);
    }
    stencil.sweep_xpbd(w, &after_lines(families));
    stencil.end_xpbd(p, h);
}

/// A compliant structural family `f`'s strain limit alone ([`xpbd::Family::limit`]),
/// when `longer(max_stretch)` finds a spring past it, to be solved along the lines
/// ([`xpbd::Family::limit_only`]); `None` without a limit, for an inextensible family
/// (its lines hold it) or with no spring past it. Projected again, a compliant family
/// would be twice as stiff; a sweep of its limit moved a line's tension one constraint
/// a substep, so a flag's top edge in a gale stayed 19% long under a 10% limit at 30
/// substeps; along its lines the limit holds at once. With no spring past it nothing is
/// solved (a sweep that moved nothing was a sixth of the crowd's step on denim).
fn limit_past(f: xpbd::Family, longer: impl FnOnce(f32) -> bool) -> Option<xpbd::Family> {
    let limited = f.on && f.compliance > 0.0 && f.max_stretch.is_finite();
    (limited && longer(f.max_stretch)).then(|| xpbd::Family::limit(f.max_stretch))
}

/// How many times at most the strain limit is solved along the lines at the end of a
/// step ([`limit_at_end`]): a solve is a Newton step, and the columns' solve stretches
/// the rows a little, so one left a flag with self-collision in a 10 m/s gale at 10.1%
/// (from 23.7%) and a second at 10.0%.
const LIMIT_SOLVES_AT_END: usize = 3;

/// The structural strain limit solved along the lines once more in the step's last
/// substep, after self-contact (up to [`LIMIT_SOLVES_AT_END`] times, while a spring is
/// past it): what self-contact does after the constraints (a fold's layers pushed apart
/// stretch them: a flag with self-collision in a 10 m/s gale stretched 24%), and what a
/// substep too long for its linearised line solve leaves (a denim curtain capped at one
/// or two substeps by a frame budget: 27% at the step's end), is taken back before the
/// step is drawn and measured. Positions only: the velocities stay as the substeps left
/// them, so the correction adds no energy. The motion constraints and contact come after
/// it, so a skinned cloth stays within its painted distances and no particle is left
/// inside a body; what contact itself stretches (a cloth wrapped round a pole thinner
/// than its edges are long, pushed out radially) stays.
fn limit_at_end(cloth: &mut ClothSolver) {
    let f = families(&cloth.params, cloth.clock.h)[SpringKind::Structural as usize];
    for _ in 0..LIMIT_SOLVES_AT_END {
        let (x, w) = (&cloth.particles.position, &cloth.particles.inv_mass);
        let springs = &cloth.structure.springs;
        let longer = |max| springs.any_longer_than(SpringKind::Structural, x, w, max);
        let Some(limit) = limit_past(f, longer) else {
            return;
        };
        // An infinite substep: the moves change no velocity.
        let still = f32::INFINITY;
        let p = &mut cloth.particles;
        match (&mut cloth.structure.stencil, &mut cloth.model) {
            (Some(stencil), _) => {
                // Nothing damped: the substep's start positions are not loaded.
                stencil.begin_xpbd(p, &[xpbd::Family::default(); 5]);
                stencil.solve_lines(&p.inv_mass, limit);
                stencil.end_xpbd(p, still);
            }
            (None, ModelState::Xpbd(constraints)) => constraints.chains.solve(p, limit, still),
            _ => return,
        }
    }
}

/// Whether the shear family is swept after the lines instead of before: when it and the
/// structural family are inextensible. Swept before, it met the lines' moves a substep
/// late: a 256 × 256 cloth hung from its top row at one substep a frame stretched 6.8%
/// (0.32% swept both before and after, 0.048% after only).
fn shear_after_lines(families: &[xpbd::Family; 5]) -> bool {
    let (structural, shear) = (SpringKind::Structural as usize, SpringKind::Shear as usize);
    families[structural].on
        && families[structural].compliance == 0.0
        && families[shear].compliance == 0.0
}

/// What is swept after the lines: the seams again (they pull against them: swept only
/// before the lines, a seam of the T-shirt stayed 3.5 mm open) and, for an inextensible
/// structural family, what bounds its length: the family projected on its own nonlinear
/// lengths (the T-shirt's armpits, where seams meet, stretched to 8.5% without it and
/// 5.2% with it), an inextensible shear family before it ([`shear_after_lines`]). A
/// compliant family's strain limit is solved along the lines instead ([`limit_past`]).
fn after_lines(families: &[xpbd::Family; 5]) -> [xpbd::Family; 5] {
    let (structural, seam) = (SpringKind::Structural as usize, SpringKind::Seam as usize);
    let mut after = [xpbd::Family::default(); 5];
    after[seam] = families[seam];
    let f = families[structural];
    if f.on && f.compliance == 0.0 {
        // Inextensible: a second, nonlinear projection is one more iteration.
        after[structural] = f;
        if shear_after_lines(families) {
            after[SpringKind::Shear as usize] = families[SpringKind::Shear as usize];
        }
    }
    after
}

/// How many substeps the hinges' projection in the current substep stands for, with
/// hinges every `every` substeps: `every` at each `every`-th substep, what is left at the
/// step's last, 0 (none) otherwise.
fn hinge_group(every: u32, clock: &Clock) -> u32 {
    let (every, done) = (every.max(1), clock.substep_index + 1);
    match done % every {
        0 => every,
        left if done == clock.substeps => left,
        _ => 0,
    }
}

/// One sweep of `families` (those on): on the grid's stencil, or colour by colour.
fn sweep_families(
    stencil: &mut Option<Stencil>,
    constraints: &mut xpbd::Constraints,
    p: &mut Particles,
    families: &[xpbd::Family; 5],
    h: f32,
) {
    if !families.iter().any(|f| f.on) {
        return;
    }
    match stencil {
        Some(stencil) => stencil.project_xpbd(p, families, h),
        None => constraints.project(p, families, h),
    }
}

/// Builds the tethers to the pins again when the pins, the torn springs or the
/// material's bounds changed (`tethers.rs`); drops them when switched off. A family's
/// length is bounded when it is inextensible (the tether's slack 0) or strain limited
/// (the slack the limit); the slack is the larger of the bounded families'.
fn refresh_tethers(cloth: &mut ClothSolver, params: &XpbdParams) {
    let bounds = [
        cloth.family_bound(SpringKind::Structural),
        cloth.family_bound(SpringKind::Shear),
    ];
    let ModelState::Xpbd(constraints) = &mut cloth.model else {
        return;
    };
    let on = params.tethers && bounds[0].is_some();
    let pins: &[u32] = if on { &cloth.drivers.pins } else { &[] };
    let slack = bounds.iter().flatten().fold(0.0f32, |a, &b| a.max(b));
    constraints.tethers.refresh(
        &cloth.structure.springs,
        cloth.structure.torn_count,
        pins,
        bounds.map(|b| b.is_some()),
        slack,
        cloth.particles.len(),
    );
}
