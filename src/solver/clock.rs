//! The step's clock: simulated time, the substep length, and where a step is among its
//! substeps. It moves in one place, [`Clock::advance`] at the end of each substep, so the
//! pins' path and the colliders' sweep read the same fraction of the step.

use super::substeps::SubstepCache;
use super::xpbd_substeps::SubstepLoop;

/// Time and substeps of a cloth.
#[derive(Clone, Debug, Default)]
pub(super) struct Clock {
    /// Simulated time since the last reset, s.
    pub time: f32,
    /// Current substep length `h`.
    pub h: f32,
    /// The previous step's `h`, to rescale Verlet's implicit velocity when `h` changes.
    pub last_h: f32,
    /// Substeps of the current (or last) step.
    pub substeps: u32,
    /// Substeps of the current step already taken.
    pub substep_index: u32,
    /// The automatic substeps hit their cap in the current step, or the strain limiter's
    /// sweeps ran out of its budget.
    pub under_resolved: bool,
    /// The most automatic substeps a step of XPBD may take, set from outside
    /// ([`ClothSolver::set_substep_budget`](super::ClothSolver::set_substep_budget)):
    /// a frame budget's share. `None`: only the cloth's own cap.
    pub budget: Option<u32>,
    /// XPBD needed more substeps than its budget in the current step.
    pub over_budget: bool,
    /// The strain limiter's sweeps until within that the current step has left
    /// (`limits::limiter_budget`).
    pub limiter_sweeps_left: u32,
    /// Automatic substeps remembered for (parameters, dt) (see [`SubstepCache`]).
    pub substep_cache: SubstepCache,
    /// XPBD's measured substeps of the last step, for (parameters, dt); empty after a
    /// reset.
    pub xpbd_loop: SubstepLoop,
    /// For XPBD's least substeps with a fabric (`ClothSolver::fabric_floor`): the
    /// parameters they were taken for, the free particles' mean inverse mass and the
    /// hinges' mean load.
    pub fabric_loads: Option<(crate::params::ClothParams, f32, f32)>,
}

impl Clock {
    /// Back to time zero, with nothing remembered of earlier steps' substeps but the
    /// stable bound (which depends only on the parameters).
    pub fn reset(&mut self) {
        self.time = 0.0;
        self.last_h = 0.0;
        self.xpbd_loop = SubstepLoop::default();
    }

    /// Starts a step of `dt` in `n` substeps. Returns `h / last_h` when the substep length
    /// changed since the last step (Verlet rescales its implicit velocity by it).
    pub fn begin(&mut self, dt: f32, n: u32) -> Option<f32> {
        self.substeps = n;
        self.limiter_sweeps_left = crate::limits::limiter_budget(n);
        self.substep_index = 0;
        self.h = dt / n as f32;
        let ratio = (self.last_h > 0.0 && self.last_h != self.h).then(|| self.h / self.last_h);
        self.last_h = self.h;
        ratio
    }

    /// The fraction of the step done at the end of the current substep.
    pub fn end_of_substep(&self) -> f32 {
        (self.substep_index + 1) as f32 / self.substeps.max(1) as f32
    }

    /// The time left in the step after the current substep, s.
    pub fn left_after_substep(&self) -> f32 {
        self.substeps.saturating_sub(self.substep_index + 1) as f32 * self.h
    }

    /// Ends the current substep: the one place the clock moves.
    pub fn advance(&mut self) {
        self.substep_index += 1;
        self.time += self.h;
    }

    /// The length of the current step, s.
    pub fn step_length(&self) -> f32 {
        self.h * self.substeps as f32
    }
}
