//! Which colliders a chain can touch during a step (the broad phase): a collider on a layer of the chain's
//! mask whose swept bounding sphere meets the chain's. The engine asks when it decides whether a chain is
//! still, and the lane solver asks again for the chains it steps, so neither keeps a list per chain.

use glam::Vec3;

use super::arena::Arena;
use super::chain::Chain;
use super::collider::{Collider, ColliderSweep};
use super::math::Transform;

/// What the broad phase needs of a step: every collider and its sweeps.
pub(crate) struct Reach<'a> {
    pub colliders: &'a Arena<Collider>,
    /// Collider slots in creation order (the sweeps' order).
    pub order: &'a [u32],
    /// Every collider's sweep in every substep: `[substep * colliders + collider]`.
    pub sweeps: &'a [ColliderSweep],
    pub substeps: usize,
    /// `EngineSettings::scale` (for the chains' collision radii).
    pub scale: f32,
}

impl Reach<'_> {
    /// Writes into `out` the indices (in collider order) of the colliders `chain` can touch while its anchor
    /// moves from `start` to `target`; when it can collide at all, its scaled collision radii into `radii`.
    pub fn candidates(
        &self,
        chain: &Chain,
        start: &Transform,
        target: &Transform,
        out: &mut Vec<usize>,
        radii: &mut Vec<f32>,
    ) {
        out.clear();
        let count = self.order.len();
        if chain.params.collision_mask == 0 || count == 0 || self.substeps == 0 {
            return;
        }
        chain.scaled_radii(self.scale, radii);
        let thickest = radii.iter().copied().fold(0.0, f32::max);
        let reach = chain.rest.positions[0].length() + chain.reach() + thickest;
        let chain_bound = Bound::of_motion(start.position, target.position, reach);
        for (c, &slot) in self.order.iter().enumerate() {
            let collider = self.colliders.at(slot as usize).expect("live");
            let (first, last) = self.first_and_last(c);
            let bound = Bound::of_motion(
                first.start.centre.as_vec3(),
                last.end.centre.as_vec3(),
                collider.shape.bounding_radius(),
            );
            if chain.params.collision_mask & collider.layers != 0 && chain_bound.touches(&bound) {
                out.push(c);
            }
        }
    }

    /// Collider `c`'s sweeps in the first and the last substep.
    pub fn first_and_last(&self, c: usize) -> (&ColliderSweep, &ColliderSweep) {
        let count = self.order.len();
        (&self.sweeps[c], &self.sweeps[(self.substeps - 1) * count + c])
    }
}

/// A sphere holding everything an object may reach during one step.
struct Bound {
    centre: Vec3,
    radius: f32,
}

impl Bound {
    /// Of an object reaching `reach` around a point that moves from `from` to `to`.
    fn of_motion(from: Vec3, to: Vec3, reach: f32) -> Self {
        Self { centre: (from + to) * 0.5, radius: (to - from).length() * 0.5 + reach }
    }

    fn touches(&self, other: &Bound) -> bool {
        (self.centre - other.centre).length() <= self.radius + other.radius
    }
}
