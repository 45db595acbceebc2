//! Which colliders a chain can touch during a step (the broad phase): a collider on a layer of the chain's
//! mask whose swept bounding sphere meets the chain's, or, for a ground plane, whose half-space it reaches.
//! The engine asks when it decides whether a chain is still (for the chains of the lane solver, only where the
//! chain could be: its anchor and rest shape stay), and the lane solver asks for the chains it steps, so
//! neither keeps a list per chain.

use glam::Vec3;

use super::arena::Arena;
use super::chain::Chain;
use super::collider::{Collider, ColliderShape, ColliderSweep};
use super::math::Transform;

/// Share of a chain's length by which its joints may end a step beyond it: a substep ends on a contact pass,
/// which can leave segments stretched (by 2 % while a fast capsule hits a chain: docs/robustness.md), and a
/// stalled direct solve accepts relative errors up to 1e-3.
const STRETCH_SLACK: f32 = 0.05;

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
        let reach = chain.rest.positions[0].length() + chain.reach() * (1.0 + STRETCH_SLACK) + thickest;
        let chain_bound = Bound::of_motion(start.position, target.position, reach);
        for (c, &slot) in self.order.iter().enumerate() {
            let collider = self.colliders.at(slot as usize).expect("live");
            if chain.params.collision_mask & collider.layers == 0 {
                continue;
            }
            let (first, last) = self.first_and_last(c);
            let reachable = match collider.shape {
                ColliderShape::Plane => chain_bound.reaches_plane(first, last),
                shape => chain_bound.touches(&Bound::of_motion(
                    first.start.centre.as_vec3(),
                    last.end.centre.as_vec3(),
                    shape.bounding_radius(),
                )),
            };
            if reachable {
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

    /// Whether the bound reaches a ground plane (the half-space below its local XZ plane) that moves from
    /// `first`'s start pose to `last`'s end pose. A plane still during the step (the usual ground) is out of
    /// reach when the bound lies wholly above it; a moving one counts as reachable.
    fn reaches_plane(&self, first: &ColliderSweep, last: &ColliderSweep) -> bool {
        let (from, to) = (first.start, last.end);
        if from.centre != to.centre || from.rotation != to.rotation {
            return true;
        }
        let centre = from.centre.as_vec3();
        let offset = self.centre - centre;
        let height = offset.dot(from.rotation * Vec3::Y);
        // A margin for the float32 rounding of the height: it grows with the sizes involved and with the
        // distances from the plane's centre and from the engine origin.
        let rounding = 1e-5 * (height.abs() + self.radius) + 1e-6 * (offset.length() + centre.length());
        height <= self.radius + rounding
    }
}

#[cfg(test)]
mod tests {
    use glam::{DVec3, Quat};

    use super::*;
    use crate::core::collider::ColliderPose;

    fn plane(centre: DVec3, rotation: Quat) -> ColliderSweep {
        let pose = ColliderPose { centre, rotation };
        ColliderSweep { shape: ColliderShape::Plane, start: pose, end: pose }
    }

    #[test]
    fn a_bound_wholly_above_a_still_plane_does_not_reach_it() {
        let ground = plane(DVec3::ZERO, Quat::IDENTITY);
        let bound = |y: f32| Bound { centre: Vec3::new(3.0, y, -2.0), radius: 0.5 };
        assert!(!bound(0.6).reaches_plane(&ground, &ground));
        assert!(bound(0.5).reaches_plane(&ground, &ground), "touching");
        assert!(bound(0.2).reaches_plane(&ground, &ground));
        assert!(bound(-4.0).reaches_plane(&ground, &ground), "below the ground is inside it");
        // A wall: the plane's Y axis along world X.
        let wall = plane(DVec3::new(1.0, 0.0, 0.0), Quat::from_rotation_z(-std::f32::consts::FRAC_PI_2));
        assert!(!Bound { centre: Vec3::new(1.6, 5.0, 0.0), radius: 0.5 }.reaches_plane(&wall, &wall));
        assert!(Bound { centre: Vec3::new(1.4, 5.0, 0.0), radius: 0.5 }.reaches_plane(&wall, &wall));
    }

    #[test]
    fn a_moving_plane_is_always_in_reach() {
        let (from, mut to) = (plane(DVec3::ZERO, Quat::IDENTITY), plane(DVec3::ZERO, Quat::IDENTITY));
        to.end.centre.y = 0.01;
        assert!(Bound { centre: Vec3::new(0.0, 100.0, 0.0), radius: 0.5 }.reaches_plane(&from, &to));
        let tilted = plane(DVec3::ZERO, Quat::from_rotation_x(0.1));
        assert!(Bound { centre: Vec3::new(0.0, 100.0, 0.0), radius: 0.5 }.reaches_plane(&from, &tilted));
    }
}
