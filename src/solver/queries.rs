//! What a cloth can be asked between steps: its particles, springs, faces, pins,
//! pieces, the model's state, counts and the clock.

use bevy::math::Vec3;

use super::patches::Patches;
use super::shape_matching::ShapeMatching;
use super::{ClothSolver, Particles, SpringKind, Springs, family_stiffness, steps};
use crate::params::Model;

impl ClothSolver {
    /// The patch model's state (part lattice and targets), if that is the model.
    pub fn patches(&self) -> Option<&Patches> {
        self.model.patches()
    }

    /// The shape-matching goals (after the last goal computation), if that is the model.
    pub fn goals(&self) -> Option<&[Vec3]> {
        self.model.shape_matching().map(|s| &s.goals[..])
    }

    /// The shape-matching state, if that is the model.
    pub fn shape_matching(&self) -> Option<&ShapeMatching> {
        self.model.shape_matching()
    }

    /// Computes the shape-matching goals of the current positions now (outside a step).
    pub fn update_goals(&mut self) {
        let model = self.params.model;
        steps::model_steps(&model).build(self, true);
    }

    /// The acting stiffness of a spring kind under the current parameters (0 for every
    /// kind when the model has no springs; XPBD's constraints have the springs'
    /// stiffness, `inf` for an inextensible one).
    pub fn stiffness(&self, kind: SpringKind) -> f32 {
        if !matches!(self.params.model, Model::MassSpring | Model::Xpbd(_)) {
            return 0.0;
        }
        family_stiffness(&self.params.springs_in_use(), kind)
    }

    /// Particle state (positions, velocities, masses, forces).
    pub fn particles(&self) -> &Particles {
        &self.particles
    }

    /// Mutable particle state, for tools that move particles (grab) between steps.
    pub fn particles_mut(&mut self) -> &mut Particles {
        self.disturbed = true;
        &mut self.particles
    }

    /// Particle positions in world space.
    pub fn positions(&self) -> &[Vec3] {
        &self.particles.position
    }

    /// The springs, torn ones included (see `Springs::alive`).
    pub fn springs(&self) -> &Springs {
        &self.structure.springs
    }

    /// Each particle's rest position in the cloth's own frame (as built, before
    /// [`frame`](Self::frame) places it).
    pub fn rest_positions(&self) -> &[Vec3] {
        &self.structure.local_rest
    }

    /// All triangles, hidden ones included.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.structure.triangles
    }

    /// For each triangle, the springs along its edges (`u32::MAX` where none).
    pub fn triangle_springs(&self) -> &[[u32; 3]] {
        &self.structure.triangle_springs
    }

    /// Whether each triangle is still drawn (false once a spring on its edge tore).
    pub fn triangle_visible(&self) -> &[bool] {
        &self.structure.triangle_visible
    }

    /// True once after faces were hidden (or on a new cloth); clears the flag.
    pub fn take_faces_changed(&mut self) -> bool {
        std::mem::take(&mut self.structure.faces_changed)
    }

    /// The indices of the pinned particles.
    pub fn pins(&self) -> &[u32] {
        &self.drivers.pins
    }

    /// The name and particle range of each garment piece (one range holding every
    /// particle for other cloths).
    pub fn pieces(&self) -> &[(String, std::ops::Range<u32>)] {
        &self.structure.pieces
    }

    /// The particles of the named run (a garment file's `runs`), or `None`.
    pub fn run(&self, name: &str) -> Option<&[u32]> {
        self.structure
            .runs
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, particles)| particles.as_slice())
    }

    /// `(width, height)` for a grid cloth.
    pub fn grid_size(&self) -> Option<(u32, u32)> {
        self.structure.grid
    }

    /// The distance self-collision keeps particles apart in the last step, m (0 when
    /// off, or for a model without it).
    pub fn self_collision_distance(&self) -> f32 {
        self.self_contact.distance()
    }

    /// The pairs self-collision listed for the last step (0 when off).
    pub fn self_collision_pairs(&self) -> usize {
        self.self_contact.pair_count()
    }

    /// How many times self-collision has listed its pairs: at most once a step, when a
    /// particle has moved out of the last list's reach.
    pub fn self_collision_listings(&self) -> u64 {
        self.self_contact.listings()
    }

    /// The pairs self-collision pushed apart in the last step (a pair counts once per
    /// substep it was pushed in).
    pub fn self_collision_pushes(&self) -> usize {
        self.self_contact.pushed()
    }

    /// Whether other cloths' particles are near enough to meet this step (after
    /// [`collide_cloths`](super::collide_cloths)): such cloths step together
    /// ([`substep_together`](super::substep_together)).
    pub fn touches_other_cloths(&self) -> bool {
        self.self_contact.touches_others()
    }

    /// Number of particles.
    pub fn particle_count(&self) -> usize {
        self.particles.len()
    }

    /// Number of springs that still act (whole and of an enabled family).
    pub fn spring_count(&self) -> usize {
        if let Some(patches) = self.model.patches() {
            return patches.spring_count();
        }
        SpringKind::ALL
            .into_iter()
            .filter(|&k| self.stiffness(k) > 0.0)
            .map(|k| {
                self.structure.springs.ranges[k as usize]
                    .clone()
                    .filter(|&s| self.structure.springs.alive[s])
                    .count()
            })
            .sum()
    }

    /// The springs torn by the last `end_step`.
    pub fn last_torn(&self) -> &[u32] {
        &self.structure.torn_this_step
    }

    /// Number of springs torn since the last reset.
    pub fn torn_count(&self) -> usize {
        self.structure.torn_count + self.model.patches().map_or(0, Patches::torn_count)
    }

    /// Simulated time since the last reset, in s.
    pub fn time(&self) -> f32 {
        self.clock.time
    }

    /// Substeps used by the last step.
    pub fn substeps(&self) -> u32 {
        self.clock.substeps
    }

    /// True when automatic substeps hit their maximum: the step may be unstable.
    pub fn under_resolved(&self) -> bool {
        self.clock.under_resolved
    }

    /// Caps the automatic substeps of XPBD at `most` a step from the next step on (at
    /// least 1; `None` lifts the cap): a frame budget's share, which the plugin sets
    /// from [`ClothBudget`](crate::ClothBudget). Below what its accuracy target asks,
    /// the cloth gives accuracy and reports it ([`StepReport::over_budget`](super::StepReport::over_budget), with
    /// the strain its constraints left in [`StepReport::solver_strain`](super::StepReport::solver_strain)). The explicit
    /// models keep their stable count whatever the cap, and a fixed count is the cloth's
    /// own choice: neither is capped.
    pub fn set_substep_budget(&mut self, most: Option<u32>) {
        self.clock.budget = most;
    }

    /// Whether [`set_substep_budget`](Self::set_substep_budget) caps this cloth: XPBD at
    /// automatic substeps.
    pub fn budget_caps(&self) -> bool {
        matches!(
            (self.params.model, self.params.substeps),
            (
                crate::params::Model::Xpbd(_),
                crate::params::Substeps::Auto { .. }
            )
        )
    }

    /// The cap [`set_substep_budget`](Self::set_substep_budget) set.
    pub fn substep_budget(&self) -> Option<u32> {
        self.clock.budget
    }

    /// True when the last step of XPBD needed more substeps than its budget allowed.
    pub fn over_budget(&self) -> bool {
        self.clock.over_budget
    }
}
