//! The named scenes of the performance benchmark: characters with hair strands, driven every frame the way
//! a host drives the engine (head sway and turn, camera, per-chain anchors, collider poses, a read-back).
//!
//! A scene says how many chains of how many joints; a [`Variant`] says which features they use. Adding a
//! variant (a future sleeping, disabled or LOD case) is one constant here and one entry in the bench's
//! variant list. The same rig (strand shapes, head motion) feeds the C ABI comparison and the rapier3d
//! peer, so every engine simulates the same chains.
#![allow(dead_code)]

use std::f32::consts::{PI, TAU};

use glam::{Quat, Vec3};
use kodawari::{AnchorSource, ChainParams, ColliderDef, ColliderShape, Engine, EngineSettings, Solver, Transform};

/// The host's frame time: a 60 Hz game.
pub const FRAME_DT: f32 = 1.0 / 60.0;
/// Chains per character: a head of hair. Colliders (head, shoulders) come per character.
pub const CHAINS_PER_CHARACTER: usize = 100;
/// Characters stand on a grid this far apart (m), so their colliders do not overlap.
const CHARACTER_SPACING: f32 = 1.5;
const CHARACTERS_PER_ROW: usize = 32;
const HEAD_HEIGHT: f32 = 1.6;
/// Strands grow from a scalp of this radius around the head joint (m).
const SCALP_RADIUS: f32 = 0.1;
/// Hair segment length (m); long chains (tails, ropes) are capped at `LONG_CHAIN_LENGTH` in total.
const HAIR_SEGMENT: f32 = 0.025;
const LONG_CHAIN_LENGTH: f32 = 0.8;
/// How fast a strand's rest shape bends toward its droop direction (rad/m).
const STRAND_CURVATURE: f32 = 6.0;
/// Camera distance from the head (m) and orbit speed (rad/s): 1.5 degrees per frame, so the blend of the
/// view shapes changes every frame.
const CAMERA_DISTANCE: f32 = 3.0;
const ORBIT_SPEED: f32 = PI / 2.0;

/// Chain lengths of a scene.
#[derive(Clone, Copy, Debug)]
pub enum JointCounts {
    Uniform(usize),
    /// Deterministic pseudo-random lengths in `min..=max` (the same every run).
    Ragged {
        min: usize,
        max: usize,
    },
}

/// A named scene: `chains` chains of `joints` joints, in characters of `CHAINS_PER_CHARACTER` chains.
#[derive(Clone, Copy, Debug)]
pub struct Scene {
    pub name: &'static str,
    pub chains: usize,
    pub joints: JointCounts,
    /// Segment length (m); `None`: hair segments, with long chains capped at `LONG_CHAIN_LENGTH` in total.
    pub segment: Option<f32>,
}

impl Scene {
    pub const fn uniform(name: &'static str, chains: usize, joints: usize) -> Self {
        Self { name, chains, joints: JointCounts::Uniform(joints), segment: None }
    }

    pub const fn ragged(name: &'static str, chains: usize, min: usize, max: usize) -> Self {
        Self { name, chains, joints: JointCounts::Ragged { min, max }, segment: None }
    }

    /// The same chains with segments of `segment` m, whatever their joint count (a 1000-joint chain of hair
    /// segments is a 25 m rope rather than a 0.8 m one of 0.8 mm segments).
    pub const fn with_segment(self, segment: f32) -> Self {
        Self { segment: Some(segment), ..self }
    }

    pub fn joint_counts(&self) -> Vec<usize> {
        match self.joints {
            JointCounts::Uniform(n) => vec![n; self.chains],
            JointCounts::Ragged { min, max } => {
                let mut rng = SplitMix64(0x6b6f_6461_7761_7269);
                (0..self.chains).map(|_| min + (rng.next() % (max - min + 1) as u64) as usize).collect()
            }
        }
    }

    pub fn total_joints(&self) -> usize {
        self.joint_counts().iter().sum()
    }

    /// Joints the solver moves (every joint but each chain's kinematic root).
    pub fn dynamic_joints(&self) -> usize {
        self.joint_counts().iter().map(|n| n - 1).sum()
    }

    /// "1000 x 16", "200 x 4-32" or "1 x 1000, 2.5 cm segments".
    pub fn shape_label(&self) -> String {
        let counts = match self.joints {
            JointCounts::Uniform(n) => format!("{} x {n}", self.chains),
            JointCounts::Ragged { min, max } => format!("{} x {min}-{max}", self.chains),
        };
        match self.segment {
            Some(segment) => format!("{counts}, {} cm segments", segment * 100.0),
            None => counts,
        }
    }
}

/// How the camera moves relative to the view reference (the head of character 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraMotion {
    /// Orbits the head: the view direction, and so the blend of the view shapes, changes every frame.
    Orbit,
    /// Rides with the head: the view direction in the head's frame never changes.
    Still,
}

/// Whether the scene has colliders and whether the chains collide with them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColliderUse {
    None,
    /// Head sphere and two shoulder capsules per character (on that character's layer) and a ground plane
    /// on every layer; each chain collides with its own character's colliders and the ground.
    Colliding,
    /// The same colliders, moving every frame, but every chain's collision mask is 0.
    MaskedOut,
}

/// How the heads move.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeadMotion {
    /// An idle animation: a few centimetres of sway and a little turning, every frame.
    Sway,
    /// Never moves (chains can come to rest and sleep).
    Still,
}

/// What state the chains are in while timed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Activity {
    /// Simulated every frame (default engine settings: they would sleep if everything stood still).
    Active,
    /// Sleeping off (`sleep_speed` 0): simulated every frame even when nothing moves.
    NeverSleep,
    /// Left to come to rest under still heads until they sleep.
    Asleep,
    /// Disabled with `set_chain_enabled(false)`.
    Disabled,
}

/// Which features the chains of a scene use, and how the frame drives them.
#[derive(Clone, Copy, Debug)]
pub struct Variant {
    /// Short name: criterion's benchmark id and the report's key.
    pub id: &'static str,
    pub label: &'static str,
    /// View shapes per chain (0 to 3: seen from the left, the right, the front).
    pub view_shapes: usize,
    pub camera: CameraMotion,
    pub colliders: ColliderUse,
    pub head: HeadMotion,
    pub activity: Activity,
    /// `EngineSettings::lod`.
    pub lod: u32,
    /// `ChainParams::stiffness`; `None`: the default.
    pub stiffness: Option<f32>,
    /// `Engine::set_solver`; `None`: the engine's default (the lane solver).
    pub solver: Option<Solver>,
}

/// No view shapes, no colliders, swaying heads: the bare rod. The camera orbits (it must not matter).
pub const PLAIN: Variant = Variant {
    id: "plain",
    label: "plain",
    view_shapes: 0,
    camera: CameraMotion::Orbit,
    colliders: ColliderUse::None,
    head: HeadMotion::Sway,
    activity: Activity::Active,
    lod: 0,
    stiffness: None,
    solver: None,
};
/// As `PLAIN` on the scalar (one chain at a time) solver instead of the default lane solver.
pub const PLAIN_SCALAR: Variant =
    Variant { id: "plain_scalar", label: "plain, scalar solver", solver: Some(Solver::Scalar), ..PLAIN };
/// As `PLAIN` with a camera that never turns: shows that a chain without view shapes ignores the camera.
pub const PLAIN_STILL: Variant =
    Variant { id: "plain_still", label: "plain, camera still", camera: CameraMotion::Still, ..PLAIN };
/// Three view shapes per chain, orbiting camera: weights and blend every frame.
pub const VIEWS: Variant = Variant { id: "views", label: "views", view_shapes: 3, ..PLAIN };
/// Three view shapes, camera still: the previous blend is reused.
pub const VIEWS_STILL: Variant =
    Variant { id: "views_still", label: "views, camera still", camera: CameraMotion::Still, ..VIEWS };
/// Colliders the chains collide with.
pub const COLLIDERS: Variant =
    Variant { id: "colliders", label: "colliders", colliders: ColliderUse::Colliding, ..PLAIN };
/// As `COLLIDERS` on the scalar solver (the lane solver runs the contact pass lane by lane).
pub const COLLIDERS_SCALAR: Variant =
    Variant { id: "colliders_scalar", label: "colliders, scalar solver", solver: Some(Solver::Scalar), ..COLLIDERS };
/// Colliders in the engine that no chain's mask selects.
pub const MASKED_COLLIDERS: Variant =
    Variant { id: "colliders_masked", label: "colliders masked out", colliders: ColliderUse::MaskedOut, ..PLAIN };
/// Everything on: view shapes with an orbiting camera and colliders.
pub const VIEWS_COLLIDERS: Variant =
    Variant { id: "views_colliders", label: "views + colliders", colliders: ColliderUse::Colliding, ..VIEWS };
/// Still heads and camera, sleeping off: the cost of a chain at rest that is still simulated.
pub const AWAKE_AT_REST: Variant = Variant {
    id: "awake_at_rest",
    label: "at rest, sleeping off",
    camera: CameraMotion::Still,
    head: HeadMotion::Still,
    activity: Activity::NeverSleep,
    ..PLAIN
};
/// The same chains after they fell asleep.
pub const ASLEEP: Variant = Variant { id: "asleep", label: "asleep", activity: Activity::Asleep, ..AWAKE_AT_REST };
/// Every chain disabled.
pub const DISABLED: Variant = Variant { id: "disabled", label: "disabled", activity: Activity::Disabled, ..PLAIN };
/// Level of detail 1 and 2: half and a quarter of the internal step rate and iterations.
pub const LOD1: Variant = Variant { id: "lod1", label: "LOD 1", lod: 1, ..PLAIN };
pub const LOD2: Variant = Variant { id: "lod2", label: "LOD 2", lod: 2, ..PLAIN };
/// No bending stiffness (an n-pendulum per chain): like for like with rapier's spherical-joint chains.
pub const LIMP: Variant = Variant { id: "limp", label: "limp (stiffness 0)", stiffness: Some(0.0), ..PLAIN };

/// Which character each chain belongs to, and the chain's place among its character's strands.
pub struct Layout {
    pub joint_counts: Vec<usize>,
    segment: Option<f32>,
    pub character_of: Vec<usize>,
    pub characters: usize,
}

impl Layout {
    pub fn new(scene: &Scene) -> Self {
        let joint_counts = scene.joint_counts();
        let character_of = (0..scene.chains).map(|i| i / CHAINS_PER_CHARACTER).collect();
        let characters = scene.chains.div_ceil(CHAINS_PER_CHARACTER);
        Self { joint_counts, segment: scene.segment, character_of, characters }
    }

    /// Strands of chain `i`'s character, and `i`'s index among them.
    fn place_on_scalp(&self, i: usize) -> (usize, usize) {
        let character = self.character_of[i];
        let first = character * CHAINS_PER_CHARACTER;
        let count = CHAINS_PER_CHARACTER.min(self.joint_counts.len() - first);
        (i - first, count)
    }

    /// Base shape of chain `i` in its anchor (head) frame, and its view shapes.
    pub fn shapes(&self, i: usize, view_shapes: usize) -> (Vec<Transform>, Vec<(Vec3, Vec<Transform>)>) {
        let (index, count) = self.place_on_scalp(i);
        let joints = self.joint_counts[i];
        let segment = self.segment.unwrap_or(HAIR_SEGMENT.min(LONG_CHAIN_LENGTH / (joints - 1) as f32));
        let base = strand(index, count, joints, segment, -Vec3::Y);
        // Seen from the left the strand curls to the left, from the right to the right, from the front
        // toward the viewer: the shapes an artist would sketch so the silhouette reads from each side.
        let views = [(-Vec3::X, -Vec3::X), (Vec3::X, Vec3::X), (Vec3::Z, Vec3::Z)];
        let views = views[..view_shapes.min(3)]
            .iter()
            .map(|&(from, lean)| (from, strand(index, count, joints, segment, (-Vec3::Y + 0.8 * lean).normalize())))
            .collect();
        (base, views)
    }
}

/// Strand `index` of `count` on the upper half of the scalp (Fibonacci spiral), `joints` joints growing
/// out of the scalp, `segment` m apart, and bending toward `droop`. Joint rotations turn the bone axis (+Y) onto the next
/// segment, as in a typical rig. Segment lengths do not depend on `droop`, as view shapes require.
pub fn strand(index: usize, count: usize, joints: usize, segment: f32, droop: Vec3) -> Vec<Transform> {
    let golden_angle = PI * (3.0 - 5f32.sqrt());
    let height = 1.0 - (index as f32 + 0.5) / count as f32;
    let ring = (1.0 - height * height).sqrt();
    let azimuth = golden_angle * index as f32;
    let mut direction = Vec3::new(ring * azimuth.cos(), height, ring * azimuth.sin());
    let mut position = direction * SCALP_RADIUS;
    let mut out = Vec::with_capacity(joints);
    for _ in 0..joints {
        out.push(Transform::new(position, Quat::from_rotation_arc(Vec3::Y, direction)));
        position += direction * segment;
        let axis = direction.cross(droop);
        let remaining = direction.angle_between(droop);
        if axis.length() > 1e-5 {
            direction = Quat::from_axis_angle(axis.normalize(), remaining.min(STRAND_CURVATURE * segment)) * direction;
        }
    }
    out
}

/// World pose of character `c`'s head at time `t` (s): swaying a few centimetres and turning a little, as an
/// idle animation does, each character with its own phase.
pub fn head_pose(c: usize, t: f32) -> Transform {
    let home = Vec3::new(
        (c % CHARACTERS_PER_ROW) as f32 * CHARACTER_SPACING,
        HEAD_HEIGHT,
        (c / CHARACTERS_PER_ROW) as f32 * CHARACTER_SPACING,
    );
    let phase = c as f32 * 0.7;
    let sway = Vec3::new(
        0.04 * (TAU * 0.5 * t + phase).sin(),
        0.015 * (TAU * 0.9 * t + phase).sin(),
        0.03 * (TAU * 0.35 * t + phase).sin(),
    );
    let turn = Quat::from_rotation_y(0.2 * (TAU * 0.25 * t + phase).sin());
    Transform::new(home + sway, turn)
}

/// Camera position for view reference `head`: in front of it, orbiting it or riding with it.
pub fn camera_position(head: &Transform, camera: CameraMotion, t: f32) -> Vec3 {
    let angle = match camera {
        CameraMotion::Orbit => ORBIT_SPEED * t,
        CameraMotion::Still => 0.0,
    };
    let offset = Quat::from_rotation_y(angle) * Vec3::new(0.0, 0.1, CAMERA_DISTANCE);
    head.transform_point(offset)
}

/// A character's colliders in its head frame: a head sphere inside the scalp and two shoulder capsules
/// lying along x (capsules are along local +Y, so they are turned by 90 degrees about z).
fn character_colliders() -> [(ColliderShape, Transform); 3] {
    let across = Quat::from_rotation_z(PI / 2.0);
    [
        (ColliderShape::Sphere { radius: 0.085 }, Transform::IDENTITY),
        (
            ColliderShape::Capsule { radius: 0.06, half_height: 0.08 },
            Transform::new(Vec3::new(-0.17, -0.27, 0.0), across),
        ),
        (
            ColliderShape::Capsule { radius: 0.06, half_height: 0.08 },
            Transform::new(Vec3::new(0.17, -0.27, 0.0), across),
        ),
    ]
}

/// The layer of character `c`'s colliders. Characters 32 apart share a layer (a chain then also tests the
/// far character's colliders, as a host with more characters than layers would see).
fn character_layer(c: usize) -> u32 {
    1 << (c % 32)
}

/// Longest an `Asleep` variant waits for its chains to come to rest (s of simulated time x 60).
const MAX_SETTLE_FRAMES: u32 = 60 * 30;

/// Time of frame `frame` (s).
pub fn frame_time(frame: u64) -> f32 {
    (frame as f64 * FRAME_DT as f64) as f32
}

/// What the host reads back after each step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReadBack {
    /// World transforms of every joint (`read_world`).
    World,
    /// Local rotations of every joint (`read_local_rotations`, what `kdw_engine_step_and_read` returns).
    LocalRotations,
}

/// A scene built in an engine and driven frame by frame as a host would.
pub struct SceneRun {
    pub engine: Engine,
    layout: Layout,
    variant: Variant,
    read_back: ReadBack,
    frame: u64,
    heads: Vec<Transform>,
    anchors: Vec<Transform>,
    collider_poses: Vec<Transform>,
    world: Vec<Transform>,
    rotations: Vec<Quat>,
}

impl SceneRun {
    /// Builds the scene at default engine settings (but for the variant's LOD, sleeping and solver). Fails only
    /// if the engine rejects part of the rig.
    pub fn new(scene: &Scene, variant: Variant, read_back: ReadBack) -> kodawari::Result<Self> {
        let defaults = EngineSettings::default();
        let sleep_speed = if variant.activity == Activity::NeverSleep { 0.0 } else { defaults.sleep_speed };
        let mut engine = Engine::new(EngineSettings { lod: variant.lod, sleep_speed, ..defaults })?;
        if let Some(solver) = variant.solver {
            engine.set_solver(solver);
        }
        let layout = Layout::new(scene);
        for i in 0..scene.chains {
            let character = layout.character_of[i];
            let collision_mask = match variant.colliders {
                ColliderUse::Colliding => character_layer(character),
                ColliderUse::None | ColliderUse::MaskedOut => 0,
            };
            let chain_defaults = ChainParams::default();
            let stiffness = variant.stiffness.unwrap_or(chain_defaults.stiffness);
            let params = ChainParams { anchor: AnchorSource::Own, collision_mask, stiffness, ..chain_defaults };
            let (base, views) = layout.shapes(i, variant.view_shapes);
            let id = engine.create_chain(params, &base)?;
            for (from, joints) in views {
                engine.add_view_shape(id, from, &joints, 1.0)?;
            }
            if variant.activity == Activity::Disabled {
                engine.set_chain_enabled(id, false)?;
            }
        }
        if variant.colliders != ColliderUse::None {
            create_colliders(&mut engine, layout.characters)?;
        }
        let joints = engine.joint_count();
        let collider_count = if variant.colliders == ColliderUse::None { 0 } else { 3 * layout.characters + 1 };
        Ok(Self {
            engine,
            variant,
            read_back,
            frame: 0,
            heads: vec![Transform::IDENTITY; layout.characters],
            anchors: vec![Transform::IDENTITY; scene.chains],
            collider_poses: vec![Transform::IDENTITY; collider_count],
            world: vec![Transform::IDENTITY; joints],
            rotations: vec![Quat::IDENTITY; joints],
            layout,
        })
    }

    /// For an `Asleep` variant, runs frames (up to `MAX_SETTLE_FRAMES`) until every chain sleeps. Returns a
    /// note for the report when not all do.
    pub fn settle(&mut self) -> Option<String> {
        if self.variant.activity != Activity::Asleep {
            return None;
        }
        let chains = self.engine.chain_count() as u32;
        let mut settled = 0;
        while self.engine.stats().chains_asleep < chains && settled < MAX_SETTLE_FRAMES {
            self.frame();
            settled += 1;
        }
        let asleep = self.engine.stats().chains_asleep;
        (asleep < chains).then(|| format!("only {asleep} of {chains} chains asleep after {settled} frames"))
    }

    /// One 60 Hz host frame: pose the heads, anchors and colliders, step, read back.
    pub fn frame(&mut self) {
        let t = frame_time(self.frame);
        self.frame += 1;
        let head_time = match self.variant.head {
            HeadMotion::Sway => t,
            HeadMotion::Still => 0.0,
        };
        for (c, head) in self.heads.iter_mut().enumerate() {
            *head = head_pose(c, head_time);
        }
        for (anchor, &c) in self.anchors.iter_mut().zip(&self.layout.character_of) {
            *anchor = self.heads[c];
        }
        if !self.collider_poses.is_empty() {
            pose_colliders(&self.heads, &mut self.collider_poses);
            self.engine.set_collider_transforms(self.collider_poses.iter().copied()).expect("valid collider poses");
        }
        let k = self.heads[0];
        let camera = camera_position(&k, self.variant.camera, t);
        self.engine.step_with_anchors(self.anchors.iter().copied(), FRAME_DT, camera, k).expect("valid step");
        match self.read_back {
            ReadBack::World => {
                self.engine.read_world(&mut self.world).expect("buffer fits");
            }
            ReadBack::LocalRotations => {
                self.engine.read_local_rotations(&mut self.rotations).expect("buffer fits");
            }
        }
    }

    /// Internal substeps the last frame ran.
    pub fn substeps_last_frame(&self) -> u32 {
        self.engine.stats().substeps_last_step
    }

    pub fn layout(&self) -> &Layout {
        &self.layout
    }
}

/// The colliders of `characters` characters (see [`ColliderUse::Colliding`]), in the order
/// [`pose_colliders`] writes their poses.
fn create_colliders(engine: &mut Engine, characters: usize) -> kodawari::Result<()> {
    for c in 0..characters {
        let head = head_pose(c, 0.0);
        for (shape, local) in character_colliders() {
            let def = ColliderDef { shape, transform: head.mul(&local), layers: character_layer(c) };
            engine.create_collider(&def)?;
        }
    }
    let ground = ColliderDef { shape: ColliderShape::Plane, transform: Transform::IDENTITY, layers: u32::MAX };
    engine.create_collider(&ground)?;
    Ok(())
}

/// World poses of every collider for this frame's `heads` (the ground stays put).
fn pose_colliders(heads: &[Transform], out: &mut [Transform]) {
    let locals = character_colliders();
    for (c, head) in heads.iter().enumerate() {
        for (k, (_, local)) in locals.iter().enumerate() {
            out[3 * c + k] = head.mul(local);
        }
    }
    out[3 * heads.len()] = Transform::IDENTITY;
}

/// A small deterministic generator (SplitMix64) for the ragged chain lengths.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}
