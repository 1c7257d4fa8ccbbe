//! Building a cloth from a layout, putting it back at rest, and tearing it by hand.

use bevy::math::{Affine3A, Vec3};

use super::clock::Clock;
use super::contact::Contact;
use super::drivers::Drivers;
use super::structure::Structure;
use super::{ClothSolver, Layout, ModelState, Particles, check_model_fits};
use crate::error::ClothError;
use crate::params::{ClothParams, Model};

impl ClothSolver {
    /// Builds a cloth of `layout` placed by `frame` (local → world), with the particles
    /// `pins` held where they start (indices into the layout's positions).
    pub fn new(
        layout: Layout,
        pins: &[u32],
        params: &ClothParams,
        frame: Affine3A,
    ) -> Result<Self, ClothError> {
        layout.validate()?;
        let count = layout.positions.len();
        if let Some(&index) = pins.iter().find(|&&i| i as usize >= count) {
            return Err(ClothError::PinOutOfRange { index, count });
        }
        params.validate()?;
        check_model_fits(params, layout.grid, !layout.triangles.is_empty())?;
        crate::params::check_work(count, params)?;
        let structure = Structure::new(layout);
        super::check_fabric_masses(params, &structure.area)?;
        let mut cloth = ClothSolver {
            particles: Particles::with_len(count),
            structure,
            drivers: Drivers::new(pins, frame),
            contact: Contact::default(),
            self_contact: Default::default(),
            clock: Clock::default(),
            params: *params,
            model: ModelState::None,
            stepping: Model::MassSpring,
            switch: None,
            disturbed: true,
            report: Default::default(),
            checkpoint: Default::default(),
            teleport_request: None,
            drivers_motion: None,
            felt: Default::default(),
            wind: Default::default(),
            touched: Vec::new(),
            air: Default::default(),
        };
        cloth.clock.substeps = 1;
        if params.fabric.is_some() {
            cloth.structure.build_hinges();
        }
        cloth.reset();
        Ok(cloth)
    }

    /// Puts every particle back at its rest position in the current frame, at rest, with
    /// every spring whole and the clock at zero.
    pub fn reset(&mut self) {
        self.disturbed = true;
        self.switch = None;
        match &mut self.model {
            ModelState::ShapeMatching(sm) => sm.reset(),
            // Rebuilt from the rest state by the next step.
            ModelState::Patches(_) => self.model = ModelState::None,
            ModelState::None | ModelState::Xpbd(_) => {}
        }
        let masses: Vec<f32> = (0..self.particles.len())
            .map(|i| self.particle_mass(i))
            .collect();
        let p = &mut self.particles;
        for (i, local) in self.structure.local_rest.iter().enumerate() {
            let x = self.drivers.frame.transform_point3(*local);
            p.position[i] = x;
            p.previous[i] = x;
            p.velocity[i] = Vec3::ZERO;
            p.residue[i] = Vec3::ZERO;
            p.force[i] = Vec3::ZERO;
            p.mass[i] = masses[i];
            p.inv_mass[i] = 1.0 / p.mass[i];
        }
        // Attachments are dropped (their owner attaches again on its next step).
        self.drivers.reset(p);
        self.structure.mend();
        self.clock.reset();
        self.report = Default::default();
        self.save_checkpoint();
    }

    /// Particle `i`'s mass under the current parameters: with a fabric its areal
    /// density times the particle's share of the triangles' area, else `node_mass` (times
    /// the particles a patch-model node stands for).
    pub(super) fn particle_mass(&self, i: usize) -> f32 {
        match &self.params.fabric {
            Some(fabric) => fabric.areal_density * self.structure.area[i],
            None => self.params.node_mass * self.particles.represents[i],
        }
    }

    /// Tears spring `s` by hand (e.g. a cut with the mouse). Returns false if it was
    /// already torn or does not exist.
    pub fn tear(&mut self, s: u32) -> bool {
        let k = s as usize;
        if k >= self.structure.springs.len() || !self.structure.springs.alive[k] {
            return false;
        }
        self.disturbed = true;
        self.structure.tear(k);
        self.structure.torn_count += 1;
        true
    }

    /// Springs stretched past the tear ratio break and hide the faces they border (Sladović
    /// 2014 §3.2): the models whose springs act on the particles (mass-spring, XPBD).
    pub(super) fn tear_overstretched(&mut self) {
        if let Some(ratio) = self.params.tear_ratio {
            self.structure
                .tear_overstretched(&self.particles.position, ratio);
        }
    }
}
