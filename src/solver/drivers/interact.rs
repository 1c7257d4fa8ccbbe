//! Tools a user applies to a running cloth: grabbing a particle, cutting along a stroke.

use bevy::math::Vec3;

use crate::solver::ClothSolver;

/// A particle held by a tool: it moves to `target` over the next step, like a pin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grab {
    /// The held particle.
    pub particle: u32,
    /// Where it was at the start of the step.
    pub(in crate::solver) from: Vec3,
    /// Where the tool wants it.
    pub target: Vec3,
    /// Its inverse mass before it was grabbed (restored on release).
    pub(in crate::solver) inv_mass: f32,
}

impl ClothSolver {
    /// The particle nearest to a ray (`origin`, unit `direction`) within `radius` of it,
    /// with its distance along the ray; hidden (torn-off) particles count too.
    pub fn nearest_particle_to_ray(
        &self,
        origin: Vec3,
        direction: Vec3,
        radius: f32,
    ) -> Option<(u32, f32)> {
        let d = direction.normalize_or_zero();
        let mut best: Option<(u32, f32, f32)> = None;
        for (i, x) in self.particles.position.iter().enumerate() {
            let along = (*x - origin).dot(d);
            if along <= 0.0 {
                continue;
            }
            let off = (*x - origin - d * along).length();
            if off <= radius && best.is_none_or(|(_, _, b)| off < b) {
                best = Some((i as u32, along, off));
            }
        }
        best.map(|(i, along, _)| (i, along))
    }

    /// Grabs particle `i`: from the next step on it moves to the target given by
    /// [`drag_grab`](Self::drag_grab) and pulls the cloth along. Returns false for a bad
    /// index. Grabbing a second particle releases the first.
    pub fn grab(&mut self, i: u32) -> bool {
        if i as usize >= self.particles.len() {
            return false;
        }
        self.release_grab();
        self.disturbed = true;
        let x = self.particles.position[i as usize];
        self.drivers.grab = Some(Grab {
            particle: i,
            from: x,
            target: x,
            inv_mass: self.particles.inv_mass[i as usize],
        });
        self.particles.inv_mass[i as usize] = 0.0;
        true
    }

    /// Moves the grabbed particle's target.
    pub fn drag_grab(&mut self, target: Vec3) {
        if let Some(g) = &mut self.drivers.grab
            && target.is_finite()
            && target != g.target
        {
            g.target = target;
            self.disturbed = true;
        }
    }

    /// Lets go of the grabbed particle; it keeps its velocity.
    pub fn release_grab(&mut self) {
        if let Some(g) = self.drivers.grab.take() {
            self.disturbed = true;
            // A pinned particle stays pinned; a free one takes the current mass.
            self.particles.inv_mass[g.particle as usize] = if g.inv_mass == 0.0 {
                0.0
            } else {
                1.0 / self.particles.mass[g.particle as usize]
            };
        }
    }

    /// The current grab, if any.
    pub fn grabbed(&self) -> Option<Grab> {
        self.drivers.grab
    }

    /// Cuts every whole spring that crosses the triangle `(a, b, c)`: a stroke seen from
    /// a camera at `a` sweeps the triangle from the camera through the cursor's old and
    /// new positions (`b`, `c` far along those rays). Returns how many springs tore; the
    /// faces along them stop being drawn.
    pub fn cut(&mut self, a: Vec3, b: Vec3, c: Vec3) -> usize {
        let mut count = 0;
        for s in 0..self.structure.springs.len() {
            if !self.structure.springs.alive[s] {
                continue;
            }
            let p = self.particles.position[self.structure.springs.a[s] as usize];
            let q = self.particles.position[self.structure.springs.b[s] as usize];
            if segment_crosses_triangle(p, q, a, b, c) && self.tear(s as u32) {
                count += 1;
            }
        }
        count
    }
}

/// Möller–Trumbore: does the segment `p → q` cross the triangle `(a, b, c)`?
fn segment_crosses_triangle(p: Vec3, q: Vec3, a: Vec3, b: Vec3, c: Vec3) -> bool {
    let dir = q - p;
    let (e1, e2) = (b - a, c - a);
    let h = dir.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-12 {
        return false;
    }
    let inv = 1.0 / det;
    let s = p - a;
    let u = inv * s.dot(h);
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let qv = s.cross(e1);
    let v = inv * dir.dot(qv);
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = inv * e2.dot(qv);
    (0.0..=1.0).contains(&t)
}
