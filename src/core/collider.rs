//! Colliders (SPEC 3.7): kinematic shapes attached to transforms the host moves every frame. The engine
//! owns them; this module holds their description, validation and per-substep poses. The contact pass
//! itself is in [`collision`](super::collision).

use glam::{DVec3, Quat, Vec3};

use super::arena::Id;
use super::error::{Error, Result};
use super::math::Transform;
use super::params::MAX_RADIUS;

/// The shape of a collider in its own frame. Capsules lie along the local +Y axis, centred on the origin;
/// the plane passes through the origin with its solid side below local +Y.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColliderShape {
    /// Keeps particles outside a ball of `radius` (m).
    Sphere { radius: f32 },
    /// Keeps particles outside the points within `radius` of the segment from `-half_height` to
    /// `+half_height` on local Y (m).
    Capsule { radius: f32, half_height: f32 },
    /// Keeps particles on the local +Y side.
    Plane,
    /// Keeps particles inside a ball (a skirt's range, a hood).
    InsideSphere { radius: f32 },
    /// Keeps particles inside a capsule.
    InsideCapsule { radius: f32, half_height: f32 },
}

impl ColliderShape {
    /// Radius and half height of the capsule the shape is (a sphere is a capsule of half height 0).
    pub fn capsule(&self) -> Option<(f32, f32)> {
        match *self {
            Self::Sphere { radius } | Self::InsideSphere { radius } => Some((radius, 0.0)),
            Self::Capsule { radius, half_height } | Self::InsideCapsule { radius, half_height } => {
                Some((radius, half_height))
            }
            Self::Plane => None,
        }
    }

    /// The same kind of shape with another size, validated; unused sizes must still be valid lengths.
    pub fn resized(&self, radius: f32, half_height: f32) -> Result<Self> {
        check_length("radius", radius, 0.0)?;
        check_length("half_height", half_height, 0.0)?;
        let shape = match self {
            Self::Sphere { .. } => Self::Sphere { radius },
            Self::Capsule { .. } => Self::Capsule { radius, half_height },
            Self::Plane => Self::Plane,
            Self::InsideSphere { .. } => Self::InsideSphere { radius },
            Self::InsideCapsule { .. } => Self::InsideCapsule { radius, half_height },
        };
        ColliderDef { shape, ..Default::default() }.validate()?;
        Ok(shape)
    }

    pub fn keeps_inside(&self) -> bool {
        matches!(self, Self::InsideSphere { .. } | Self::InsideCapsule { .. })
    }

    /// Distance from the frame origin within which the solid part lies (planes: unbounded).
    pub fn bounding_radius(&self) -> f32 {
        match self.capsule() {
            Some((radius, half_height)) => radius + half_height,
            None => f32::INFINITY,
        }
    }
}

/// Everything needed to create a collider.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColliderDef {
    pub shape: ColliderShape,
    /// Initial world pose; afterwards the batched `set_collider_transforms` moves it.
    pub transform: Transform,
    /// Collision layers this collider is on: a chain collides with it when `chain.collision_mask & layers`
    /// is non-zero. Default: layer 0 (bit 0).
    pub layers: u32,
}

impl Default for ColliderDef {
    fn default() -> Self {
        Self { shape: ColliderShape::Sphere { radius: 0.1 }, transform: Transform::IDENTITY, layers: 1 }
    }
}

fn check_length(name: &str, value: f32, min: f32) -> Result<()> {
    if value.is_finite() && value >= min && value <= MAX_RADIUS {
        Ok(())
    } else {
        Err(Error::invalid_argument(format!("collider {name} {value} outside [{min}, {MAX_RADIUS}] m")))
    }
}

impl ColliderDef {
    pub fn validate(&self) -> Result<()> {
        let length = check_length;
        match self.shape {
            ColliderShape::Sphere { radius } | ColliderShape::InsideSphere { radius } => {
                length("radius", radius, 0.0)?;
            }
            ColliderShape::Capsule { radius, half_height } | ColliderShape::InsideCapsule { radius, half_height } => {
                length("radius", radius, 0.0)?;
                length("half_height", half_height, 0.0)?;
                if radius == 0.0 && half_height == 0.0 {
                    return Err(Error::invalid_argument("degenerate capsule: radius and half_height are both 0"));
                }
            }
            ColliderShape::Plane => {}
        }
        if self.shape.keeps_inside() && self.shape.capsule().is_some_and(|(radius, _)| radius <= 0.0) {
            return Err(Error::invalid_argument("an inside collider needs a radius > 0"));
        }
        Ok(())
    }
}

/// Marker type for collider ids.
pub enum ColliderTag {}
pub type ColliderId = Id<ColliderTag>;

/// A collider as the engine stores it.
#[derive(Clone, Debug)]
pub(crate) struct Collider {
    pub shape: ColliderShape,
    pub layers: u32,
    /// World pose at the start and the end of the last step, and the one set for the next step.
    pub previous: Transform,
    pub current: Transform,
    pub pending: Transform,
}

impl Collider {
    pub fn new(def: &ColliderDef, pose: Transform) -> Self {
        Self { shape: def.shape, layers: def.layers, previous: pose, current: pose, pending: pose }
    }

    /// The shape's kind, for hashing.
    pub fn kind_code(&self) -> u64 {
        match self.shape {
            ColliderShape::Sphere { .. } => 0,
            ColliderShape::Capsule { .. } => 1,
            ColliderShape::Plane => 2,
            ColliderShape::InsideSphere { .. } => 3,
            ColliderShape::InsideCapsule { .. } => 4,
        }
    }
}

/// A collider's pose during one substep, relative to the engine origin.
#[derive(Clone, Copy, Debug)]
pub struct ColliderPose {
    pub centre: DVec3,
    pub rotation: Quat,
}

impl ColliderPose {
    pub fn new(t: &Transform, origin: Vec3) -> Self {
        Self { centre: (t.position - origin).as_dvec3(), rotation: t.rotation }
    }

    pub fn to_local(&self, p: DVec3) -> Vec3 {
        self.rotation.inverse() * (p - self.centre).as_vec3()
    }

    pub fn direction_to_world(&self, v: Vec3) -> DVec3 {
        (self.rotation * v).as_dvec3()
    }
}

/// What the contact pass needs of one collider during one substep: its shape and where it moved from and to.
#[derive(Clone, Copy, Debug)]
pub struct ColliderSweep {
    pub shape: ColliderShape,
    pub start: ColliderPose,
    pub end: ColliderPose,
}
