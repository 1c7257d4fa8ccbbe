//! XPBD's substeps: the count its accuracy target asks for (from the load its constraints
//! carry), the closed loop that follows the stretch each step leaves, and the floor a
//! fabric's shear and bending set; the substeps its hinges are projected every.

use super::substeps::SubstepCache;
use super::{ClothSolver, SpringKind};
use crate::params::{Model, XpbdSolve};

/// How much softer than their stiffness XPBD may hold a fabric's hinges under a steady
/// load ([`ClothSolver::fabric_floor`]): 5%.
const FABRIC_SOFTENING: f32 = 0.05;

/// XPBD's closed loop (see [`ClothSolver::xpbd_closed_loop`]): the substeps of the last
/// step for (parameters, dt), and how many steps in a row have left less than a quarter
/// of the target.
#[derive(Clone, Debug, Default)]
pub(super) struct SubstepLoop {
    last: SubstepCache,
    calm: u32,
    /// The stretch past the bound the last step left, measured at its end.
    violation: Option<f32>,
}

/// Steps in a row below a quarter of the target before the count is lowered (half a
/// second at 16 ms: longer than the bounce of a hanging cloth, so a swing's quiet
/// moments do not lower it).
const CALM_STEPS: u32 = 30;

impl SubstepLoop {
    /// Records the stretch past the bound a step left (`end_step` measures it).
    pub(super) fn measured(&mut self, violation: f32) {
        self.violation = Some(violation.max(0.0));
    }

    /// The next step's substeps from the last step's `n` and the stretch `violation` it
    /// left, toward `target`. One iteration a substep leaves a violation that scales as
    /// `h²` (Macklin et al. 2019 §4), so `n·√(violation/target)` meets the target. Above
    /// the target: that with a 10% margin, at once. Below a quarter of it for
    /// [`CALM_STEPS`] steps in a row: toward that, by at most 15%. Otherwise `n` stays.
    /// Changing the count changes how stiff one iteration is, which sets a hanging
    /// cloth moving: hence the slow, rare decrease (a count that hunted step by step kept
    /// a chain swinging at 0.15 m/s).
    fn next(&mut self, n: u32, violation: f32, target: f32) -> u32 {
        let n = n.max(1) as f32;
        let ratio = (violation.max(0.0) / target).sqrt();
        let next = if !ratio.is_finite() {
            2.0 * n
        } else if violation > target {
            (n * ratio * 1.1).ceil()
        } else if violation < target / 4.0 {
            self.calm += 1;
            if self.calm < CALM_STEPS {
                return n as u32;
            }
            (n * ratio * 1.25).max(n * 0.85).ceil()
        } else {
            n
        };
        if next != n || violation >= target / 4.0 {
            self.calm = 0;
        }
        next.clamp(1.0, u32::MAX as f32) as u32
    }
}

impl ClothSolver {
    /// XPBD's automatic substeps for `dt`: one iteration per substep makes an
    /// inextensible constraint act like a spring of stiffness about `m/h²` (Macklin et al.
    /// 2019 §4), so a cloth hanging `R` springs of length `L` under gravity `g` stretches
    /// its most loaded constraint by about `2 R g h² / L` beyond the material's own
    /// stretch (measured on hanging inextensible chains of 5, 10, 20 and 40 links at 20
    /// substeps: 1.2, 1.6, 1.8 and 1.9 × `R g h² / L`, `tests/xpbd.rs`). `L` is the mean
    /// structural rest length, `R` the cloth's longest rest extent along an axis over `L`,
    /// `g` = 9.81 m/s² (the substeps do not follow the scene's gravity). The fewest
    /// substeps with `h ≤ √(target · L / (2 R g))`. Solved along lines, tension crosses
    /// a line in one substep and only the coupling of the lines is left to the substeps:
    /// `√R` in place of `R` (the closed loop corrects it; with `1` a curtain's strain
    /// limit overshot by 2.4 points in its first gust, `tests/fabric.rs`).
    pub(super) fn xpbd_substeps(&self, dt: f32, target: f32) -> u32 {
        const G: f32 = 9.81;
        let size = super::contact::Bounds::around(&self.structure.local_rest).size();
        let l = self.structure.length_scale.max(f32::EPSILON);
        let lines = matches!(self.params.model, Model::Xpbd(x) if x.solve == XpbdSolve::Lines);
        let across = size.max_element().max(l) / l;
        let across = if lines { across.sqrt() } else { across };
        let h = (target * l / (2.0 * across * G)).sqrt();
        let n = (dt / h).ceil();
        if n.is_finite() { (n as u32).max(1) } else { 1 }
    }

    /// XPBD's automatic substeps by measurement, when its structural springs' length is
    /// bounded (inextensible, or strain limited): the first step of a run (or after the
    /// parameters or `dt` changed) takes [`Self::xpbd_substeps`]'s estimate, every later one
    /// the previous count corrected by the largest stretch the last step left beyond the
    /// bound ([`SubstepLoop::next`]), at most `cap`. `None` for the other models and for a
    /// compliant, unlimited cloth (whose own stretch the measure cannot tell from the
    /// solver's error). The same bits on any thread count: a maximum over the springs.
    pub(super) fn xpbd_closed_loop(&mut self, dt: f32, cap: u32) -> Option<u32> {
        let Model::Xpbd(xpbd) = self.params.model else {
            return None;
        };
        let allowance = self.family_bound(SpringKind::Structural)?;
        let n = match self.clock.xpbd_loop.last.get(&self.params, dt) {
            None => {
                self.clock.xpbd_loop.calm = 0;
                self.clock.xpbd_loop.violation = None;
                self.refresh_substep_cache(dt)
            }
            Some(n) => {
                // Measured by the last `end_step`; now if the steps were run by hand.
                let violation = match self.clock.xpbd_loop.violation.take() {
                    Some(v) => v,
                    None => (self.structural_strain() - allowance).max(0.0),
                };
                self.clock
                    .xpbd_loop
                    .next(n, violation, xpbd.max_stretch_error)
            }
        };
        self.clock.xpbd_loop.last.set(&self.params, dt, n.min(cap));
        Some(n)
    }

    /// XPBD's least substeps for `dt` with a fabric (0 otherwise). With its multiplier
    /// from 0 each substep, a constraint of compliance `α` holds a load as if its
    /// compliance were `α (1 + r)`, `r = h² Σ w |∇C|² / α`:
    /// - the structural and shear springs (`Σ w |∇C|² = 2 w` at the free particles' mean
    ///   `w`, `α = 1/k`) then stretch `r` times their elastic strain `ε` too far, and that
    ///   error is held to XPBD's `max_stretch_error`: `r ε ≤ max_stretch_error`, `ε` the
    ///   largest structural strain now. A stiff fabric barely stretching needs nothing
    ///   more; a knit hanging at 3.4% strain at 2.5 cm needed 20 substeps, not 10.
    ///   Without it its sag depended on the resolution: 25 mm at 5 cm, 34 mm at 2.5 cm
    ///   (`tests/fabric.rs`);
    /// - the hinges (`Σ w K²`, `α = (A0 + A1)/B`, their mean) to `r ≤` [`FABRIC_SOFTENING`].
    pub(super) fn fabric_floor(&mut self, dt: f32) -> u32 {
        let (Model::Xpbd(xpbd), Some(fabric)) = (self.params.model, self.params.fabric) else {
            return 0;
        };
        let (w, _) = self.fabric_loads();
        let (structural, shear) = fabric.grid_springs();
        // Along lines the structural family is solved exactly, with no softening (a soft
        // grid settles at its static stretch at 20 substeps, `tests/xpbd.rs`): only the
        // swept shear family bounds the substeps.
        let springs_k = match xpbd.solve {
            XpbdSolve::Lines => shear,
            XpbdSolve::Sweep => structural.max(shear),
        };
        let strain = self.structural_strain().max(0.0);
        // `h² · 2 w k · ε ≤ max_stretch_error`, and the hinges' own count.
        let springs = 2.0 * w * springs_k * strain / xpbd.max_stretch_error;
        let n = (dt * springs.sqrt()).ceil();
        let n = if n.is_finite() { (n as u32).max(1) } else { 1 };
        n.max(self.hinge_projections(dt))
    }

    /// How many substeps apart the current step of `dt` projects a fabric's hinges
    /// (XPBD; `steps/xpbd.rs`): a hinge is as soft as a cloth's bending, far softer than
    /// its stretch, so where the stretch asks for more substeps than
    /// [`Self::hinge_projections`], the hinges run once every few of them. Every substep
    /// with self-collision, which bounds how far a particle moves in one substep: a hinge
    /// projected once for several substeps gives their whole impulse in one, and in the
    /// doorway's gale (six denim strips tangling, accuracy first) a strip then passed 50%
    /// strain after 2 s with one projection for about twenty substeps, reached 36% with
    /// one for four, and 20–24% with one for two or every substep.
    pub(super) fn hinge_every(&mut self, dt: f32) -> u32 {
        if self.params.self_collision.enabled {
            return 1;
        }
        (self.clock.substeps / self.hinge_projections(dt)).max(1)
    }

    /// How many times a step of `dt` must project a fabric's hinges: the least that keeps
    /// their softening within [`FABRIC_SOFTENING`] (1 without a fabric).
    fn hinge_projections(&mut self, dt: f32) -> u32 {
        if self.params.fabric.is_none() {
            return 1;
        }
        let (_, hinges) = self.fabric_loads();
        let n = (dt * (hinges / FABRIC_SOFTENING).sqrt()).ceil();
        if n.is_finite() { (n as u32).max(1) } else { 1 }
    }

    /// The free particles' mean inverse mass and the fabric hinges' mean load
    /// (`Hinges::mean_load`), kept while the parameters stay.
    fn fabric_loads(&mut self) -> (f32, f32) {
        let bending = self.params.fabric.map_or(0.0, |f| f.bending);
        match self.clock.fabric_loads {
            Some((params, w, hinges)) if params == self.params => (w, hinges),
            _ => {
                let (sum, free) = self
                    .particles
                    .inv_mass
                    .iter()
                    .filter(|&&w| w > 0.0)
                    .fold((0.0f64, 0usize), |(s, n), &w| (s + f64::from(w), n + 1));
                let w = (sum / free.max(1) as f64) as f32;
                let hinges = self
                    .structure
                    .hinges
                    .mean_load(&self.particles.inv_mass, bending);
                self.clock.fabric_loads = Some((self.params, w, hinges));
                (w, hinges)
            }
        }
    }
}
