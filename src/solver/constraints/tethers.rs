//! Long-range attachments (Kim, Chentanez, Müller, "Long Range Attachments — A Method to
//! Simulate Inextensible Clothing in Computer Games", SCA 2012): a cloth hanging from
//! pins cannot stretch more than its material allows, so no particle can be farther from
//! a pin than the length of the shortest path to it through the cloth's rest springs,
//! times `1 + limit`. Each particle gets that bound to the nearest pin of each group of
//! pins (pins joined by springs: a rod's row is one group, a curtain's two corners are
//! two), and a substep moves a particle that is beyond it back onto it. The pin has no
//! mass to move, so the tethers do not depend on each other: one pass, in any order, on
//! any thread, gives the same bits. A hung cloth then holds its length at any size with
//! few substeps; without them the error of one iteration per substep travels down the
//! cloth one constraint a substep.
//!
//! The paths follow only the families whose length is bounded (an inextensible one, or
//! one under the strain limit); a family that may stretch could make a real path longer
//! than its rest length, and a tether on it would stiffen the cloth. Path lengths are
//! rounded up (a bound must never be too short).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use bevy::math::Vec3;

use crate::solver::parallel::{self, CHUNK, XPBD_PARALLEL_FROM};
use crate::solver::{Particles, SpringKind, Springs};

/// At most this many groups of pins get their own tethers; a cloth held by more (a cape
/// pinned at scattered points) is tethered to its nearest pin of all, as one group.
const MAX_GROUPS: usize = 4;

/// What the tethers were built from: rebuilt when any of it changes.
#[derive(Clone, Debug, Default, PartialEq)]
struct Key {
    pins: Vec<u32>,
    torn: usize,
    families: [bool; 2],
    slack: u32,
}

/// Each particle's bound to the nearest pin of each group.
#[derive(Clone, Debug, Default)]
pub(in crate::solver) struct Tethers {
    key: Option<Key>,
    /// Per group, per particle: the anchor, as its place in the pins given to
    /// [`Self::refresh`] (`u32::MAX` where none reaches).
    anchor: Vec<u32>,
    /// Per group, per particle: the largest distance allowed from the anchor, m.
    reach: Vec<f32>,
    /// Particles (and groups: `anchor.len() / n`).
    n: usize,
    /// The pins' positions in the current substep (scratch, one per pin).
    pinned: Vec<Vec3>,
}

impl Tethers {
    /// Rebuilds the tethers if the pins, the torn springs, the bounded families
    /// (structural, shear) or the slack changed since the last build; nothing otherwise.
    /// `bounded[k]`: family k's length is bounded; with the structural one unbounded, there
    /// are no tethers.
    pub fn refresh(
        &mut self,
        springs: &Springs,
        torn: usize,
        pins: &[u32],
        bounded: [bool; 2],
        slack: f32,
        n: usize,
    ) {
        let fresh = |key: &Key| {
            key.pins == pins
                && key.torn == torn
                && key.families == bounded
                && key.slack == slack.to_bits()
        };
        if self.key.as_ref().is_some_and(fresh) && self.n == n {
            return;
        }
        self.key = Some(Key {
            pins: pins.to_vec(),
            torn,
            families: bounded,
            slack: slack.to_bits(),
        });
        self.n = n;
        self.anchor.clear();
        self.reach.clear();
        if !bounded[0] || pins.is_empty() {
            return;
        }
        self.build(springs, pins, bounded, n);
        self.pinned = Vec::with_capacity(pins.len());
        let stretch = 1.0 + slack;
        for (reach, anchor) in self.reach.iter_mut().zip(&self.anchor) {
            // A pin's own entry: no tether (it does not move itself).
            if *anchor == u32::MAX || *reach == 0.0 {
                *reach = f32::INFINITY;
            } else {
                *reach *= stretch;
                *reach += *reach * f32::EPSILON * 2.0;
            }
        }
    }

    /// Each particle's nearest pin (by its place among `pins`) and rest geodesic distance
    /// to it, per group of joined pins, through the springs of the bounded families
    /// (Dijkstra, `Graph::nearest`).
    fn build(&mut self, springs: &Springs, pins: &[u32], bounded: [bool; 2], n: usize) {
        let kinds = [SpringKind::Structural, SpringKind::Shear];
        let graph = Graph::new(springs, n, |s| {
            springs.alive[s]
                && kinds
                    .iter()
                    .zip(bounded)
                    .any(|(&k, on)| on && springs.ranges[k as usize].contains(&s))
        });
        let mut groups = graph.groups(pins);
        if groups.len() > MAX_GROUPS {
            groups = vec![pins.to_vec()];
        }
        self.anchor.resize(groups.len() * n, u32::MAX);
        self.reach.resize(groups.len() * n, f32::INFINITY);
        for (g, group) in groups.iter().enumerate() {
            let range = g * n..(g + 1) * n;
            graph.nearest(
                group,
                &mut self.anchor[range.clone()],
                &mut self.reach[range],
            );
        }
        // Anchors by their place among the pins (what `project` reads them from).
        let mut slot = vec![u32::MAX; n];
        for (k, &p) in pins.iter().enumerate() {
            if slot[p as usize] == u32::MAX {
                slot[p as usize] = k as u32;
            }
        }
        for anchor in &mut self.anchor {
            if *anchor != u32::MAX {
                *anchor = slot[*anchor as usize];
            }
        }
    }

    /// Moves each free particle that is beyond its bound back onto it, group by group, and
    /// gives its velocity the move over `h` (as the constraints' corrections); `pins` as
    /// given to [`Self::refresh`], where they are now. In pieces over the compute pool: a
    /// particle's tethers read only the pins, which they never move.
    pub fn project(&mut self, p: &mut Particles, pins: &[u32], h: f32) {
        let n = self.n;
        if self.anchor.is_empty() || p.len() != n {
            return;
        }
        self.pinned.clear();
        self.pinned
            .extend(pins.iter().map(|&i| p.position[i as usize]));
        let pinned = &self.pinned[..];
        for g in 0..self.anchor.len() / n {
            let range = g * n..(g + 1) * n;
            let tethers = self.anchor[range.clone()]
                .chunks(CHUNK)
                .zip(self.reach[range].chunks(CHUNK));
            let pieces = p
                .position
                .chunks_mut(CHUNK)
                .zip(p.velocity.chunks_mut(CHUNK))
                .zip(p.inv_mass.chunks(CHUNK))
                .zip(tethers);
            parallel::for_each_from(
                XPBD_PARALLEL_FROM,
                n,
                pieces,
                |(((x, v), inv_mass), (anchor, reach))| {
                    for k in 0..x.len() {
                        if inv_mass[k] == 0.0 || anchor[k] == u32::MAX {
                            continue;
                        }
                        let d = x[k] - pinned[anchor[k] as usize];
                        let len2 = d.length_squared();
                        if len2 > reach[k] * reach[k] {
                            let correction = d * (reach[k] / len2.sqrt() - 1.0);
                            x[k] += correction;
                            v[k] += correction / h;
                        }
                    }
                },
            );
        }
    }
}

/// The cloth's bounded springs as an adjacency list (CSR) with rest lengths.
struct Graph {
    start: Vec<u32>,
    /// `(neighbour, rest length)`.
    edges: Vec<(u32, f32)>,
}

impl Graph {
    fn new(springs: &Springs, n: usize, keep: impl Fn(usize) -> bool) -> Self {
        let kept: Vec<usize> = (0..springs.len()).filter(|&s| keep(s)).collect();
        let mut start = vec![0u32; n + 1];
        for &s in &kept {
            start[springs.a[s] as usize + 1] += 1;
            start[springs.b[s] as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut edges = vec![(0u32, 0.0f32); start[n] as usize];
        for &s in &kept {
            let (a, b, l) = (springs.a[s], springs.b[s], springs.rest_length[s]);
            edges[fill[a as usize] as usize] = (b, l);
            fill[a as usize] += 1;
            edges[fill[b as usize] as usize] = (a, l);
            fill[b as usize] += 1;
        }
        Self { start, edges }
    }

    fn neighbours(&self, i: usize) -> &[(u32, f32)] {
        &self.edges[self.start[i] as usize..self.start[i + 1] as usize]
    }

    /// The pins in groups joined by springs through pins only, each group in pin order,
    /// the groups in the order of their first pin.
    fn groups(&self, pins: &[u32]) -> Vec<Vec<u32>> {
        let n = self.start.len() - 1;
        let mut group = vec![usize::MAX; n];
        let is_pin = {
            let mut is_pin = vec![false; n];
            pins.iter().for_each(|&p| is_pin[p as usize] = true);
            is_pin
        };
        let mut groups: Vec<Vec<u32>> = Vec::new();
        for &p in pins {
            if group[p as usize] != usize::MAX {
                continue;
            }
            let g = groups.len();
            let mut members = vec![p];
            group[p as usize] = g;
            let mut k = 0;
            while k < members.len() {
                for &(q, _) in self.neighbours(members[k] as usize) {
                    if is_pin[q as usize] && group[q as usize] == usize::MAX {
                        group[q as usize] = g;
                        members.push(q);
                    }
                }
                k += 1;
            }
            members.sort_unstable();
            groups.push(members);
        }
        groups
    }

    /// Dijkstra from every pin of `group` at once: each particle's nearest pin and the
    /// length of the shortest path to it (ties to the lower pin index), rounded up.
    fn nearest(&self, group: &[u32], anchor: &mut [u32], distance: &mut [f32]) {
        // Non-negative floats order as their bits.
        let mut queue = BinaryHeap::new();
        for &p in group {
            anchor[p as usize] = p;
            distance[p as usize] = 0.0;
            queue.push(Reverse((0u32, p, p)));
        }
        while let Some(Reverse((bits, from, i))) = queue.pop() {
            let d = f32::from_bits(bits);
            if d != distance[i as usize] || from != anchor[i as usize] {
                continue; // a stale entry
            }
            for &(j, length) in self.neighbours(i as usize) {
                let sum = d + length;
                let next = sum + sum * f32::EPSILON;
                let j = j as usize;
                if next < distance[j] || (next == distance[j] && from < anchor[j]) {
                    distance[j] = next;
                    anchor[j] = from;
                    queue.push(Reverse((next.to_bits(), from, j as u32)));
                }
            }
        }
    }
}
