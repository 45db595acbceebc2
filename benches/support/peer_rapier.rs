//! The peer: what a user would pick instead of kodawari for a joint chain, rapier3d (0.30, f32, single
//! thread): one rigid body per joint connected by spherical joints, either as constraints solved in maximal
//! coordinates (`ImpulseJointSet`) or as reduced-coordinate multibodies (`MultibodyJointSet`). Default
//! `IntegrationParameters` (dt 1/60 s, `num_solver_iterations` 4: rapier splits each step into that many
//! substeps of 1/240 s, like kodawari's default 240 Hz), one `PhysicsPipeline::step` per 60 Hz frame.
//!
//! The bodies model kodawari's particles: a mass at each joint and a massless link to the parent. Rapier has
//! no point masses, so each body gets the inertia of a small solid ball ([`BALL_RADIUS`]); no colliders (no
//! contacts, as in the kodawari scenes without colliders); sleeping off (kodawari does not sleep yet).
#![allow(dead_code)]

use glam::{DVec3, Vec3};
use rapier3d::prelude::*;

use super::peer_pendulum::{ROOT, Reference, rms_error};
use super::scenes::{FRAME_DT, Layout, Scene, frame_time, head_pose};

/// Radius (m) of the solid ball whose inertia each body gets: small next to every link, so the bodies act
/// as the reference's point masses, large enough for a well-conditioned solve.
pub const BALL_RADIUS: f32 = 0.005;

/// How the joints are solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointSolver {
    /// `ImpulseJointSet`: each spherical joint is a constraint between two free bodies (maximal coordinates).
    Impulse,
    /// `MultibodyJointSet`: each chain is one articulation in reduced coordinates.
    Multibody,
}

impl JointSolver {
    pub fn label(self) -> &'static str {
        match self {
            Self::Impulse => "rapier3d, impulse joints",
            Self::Multibody => "rapier3d, multibody joints",
        }
    }
}

/// Rapier's internal substeps per step at default `IntegrationParameters`.
pub fn default_substeps() -> usize {
    IntegrationParameters::default().num_solver_iterations
}

/// Everything `PhysicsPipeline::step` needs.
pub struct RapierWorld {
    gravity: Vector<Real>,
    pub params: IntegrationParameters,
    pipeline: PhysicsPipeline,
    islands: IslandManager,
    broad_phase: DefaultBroadPhase,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    ccd: CCDSolver,
    solver: JointSolver,
}

fn vector_of(v: Vec3) -> Vector<Real> {
    vector![v.x, v.y, v.z]
}

impl RapierWorld {
    pub fn new(solver: JointSolver) -> Self {
        Self {
            gravity: vector![0.0, -9.81, 0.0],
            params: IntegrationParameters::default(),
            pipeline: PhysicsPipeline::new(),
            islands: IslandManager::new(),
            broad_phase: DefaultBroadPhase::new(),
            narrow_phase: NarrowPhase::new(),
            bodies: RigidBodySet::new(),
            colliders: ColliderSet::new(),
            impulse_joints: ImpulseJointSet::new(),
            multibody_joints: MultibodyJointSet::new(),
            ccd: CCDSolver::new(),
            solver,
        }
    }

    /// A chain through the world positions `joints`: a kinematic root (fixed if `fixed_root`) and a body of
    /// `mass` kg per further joint with linear damping `damping` (1/s). Returns the bodies, root first.
    pub fn add_chain(&mut self, joints: &[Vec3], mass: f32, damping: f32, fixed_root: bool) -> Vec<RigidBodyHandle> {
        let root = if fixed_root { RigidBodyBuilder::fixed() } else { RigidBodyBuilder::kinematic_position_based() };
        let mut handles = vec![self.bodies.insert(root.translation(vector_of(joints[0])))];
        let inertia = 0.4 * mass * BALL_RADIUS * BALL_RADIUS;
        for pair in joints.windows(2) {
            let body = RigidBodyBuilder::dynamic()
                .translation(vector_of(pair[1]))
                .additional_mass_properties(MassProperties::new(
                    point![0.0, 0.0, 0.0],
                    mass,
                    vector![inertia, inertia, inertia],
                ))
                .linear_damping(damping)
                .can_sleep(false);
            let child = self.bodies.insert(body);
            // The pivot is the parent's joint; the child carries the link to it.
            let link = pair[0] - pair[1];
            let joint = SphericalJointBuilder::new()
                .local_anchor1(point![0.0, 0.0, 0.0])
                .local_anchor2(point![link.x, link.y, link.z])
                .contacts_enabled(false);
            let parent = *handles.last().expect("the root is there");
            match self.solver {
                JointSolver::Impulse => {
                    self.impulse_joints.insert(parent, child, joint, true);
                }
                JointSolver::Multibody => {
                    self.multibody_joints.insert(parent, child, joint, true).expect("a chain is a valid tree");
                }
            }
            handles.push(child);
        }
        handles
    }

    pub fn move_kinematic(&mut self, body: RigidBodyHandle, position: Vec3) {
        self.bodies[body].set_next_kinematic_translation(vector_of(position));
    }

    /// One `PhysicsPipeline::step` of `params.dt`.
    pub fn step(&mut self) {
        self.pipeline.step(
            &self.gravity,
            &self.params,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &mut self.impulse_joints,
            &mut self.multibody_joints,
            &mut self.ccd,
            &(),
            &(),
        );
    }

    pub fn position(&self, body: RigidBodyHandle) -> Vec3 {
        let t = self.bodies[body].translation();
        Vec3::new(t.x, t.y, t.z)
    }

    /// Internal substeps per `step`.
    pub fn substeps(&self) -> usize {
        self.params.num_solver_iterations
    }
}

/// The hair scene of [`scenes`](super::scenes) without view shapes and colliders (rapier has neither):
/// kinematic roots following the heads, bodies at the base shape's joints, kodawari's default particle
/// mass and damping. Rapier's chains have no bending stiffness (that would need joint motors).
pub struct RapierScene {
    pub world: RapierWorld,
    chains: Vec<Vec<RigidBodyHandle>>,
    /// Each chain's root position in its head's frame.
    roots: Vec<Vec3>,
    character_of: Vec<usize>,
    heads: Vec<kodawari::Transform>,
    read_back: Vec<Vec3>,
    frame: u64,
}

impl RapierScene {
    pub fn new(scene: &Scene, solver: JointSolver) -> Self {
        let layout = Layout::new(scene);
        let defaults = kodawari::ChainParams::default();
        let mut world = RapierWorld::new(solver);
        let mut chains = Vec::with_capacity(scene.chains);
        let mut roots = Vec::with_capacity(scene.chains);
        for i in 0..scene.chains {
            let (base, _) = layout.shapes(i, 0);
            let head = head_pose(layout.character_of[i], 0.0);
            let joints: Vec<Vec3> = base.iter().map(|t| head.transform_point(t.position)).collect();
            chains.push(world.add_chain(&joints, defaults.mass, defaults.damping, false));
            roots.push(base[0].position);
        }
        Self {
            world,
            chains,
            roots,
            heads: vec![kodawari::Transform::IDENTITY; layout.characters],
            read_back: Vec::with_capacity(scene.total_joints()),
            character_of: layout.character_of,
            frame: 0,
        }
    }

    /// One 60 Hz frame: move the roots with the heads, step, read every body's position.
    pub fn frame(&mut self) {
        // The heads' poses of this frame, as the kodawari scene passes them.
        let t = frame_time(self.frame);
        self.frame += 1;
        for (c, head) in self.heads.iter_mut().enumerate() {
            *head = head_pose(c, t);
        }
        for ((chain, root), &c) in self.chains.iter().zip(&self.roots).zip(&self.character_of) {
            self.world.move_kinematic(chain[0], self.heads[c].transform_point(*root));
        }
        self.world.step();
        self.read_back.clear();
        for chain in &self.chains {
            self.read_back.extend(chain.iter().map(|&b| self.world.position(b)));
        }
    }

    /// Largest distance of any body from where its chain's root is, over the chain length: a broken or
    /// exploding chain shows up as a value far above 1.
    pub fn worst_reach(&self) -> f32 {
        let mut worst = 0.0f32;
        for chain in &self.chains {
            let root = self.world.position(chain[0]);
            let length: f32 =
                chain.windows(2).map(|w| (self.world.position(w[1]) - self.world.position(w[0])).length()).sum();
            for &b in &chain[1..] {
                worst = worst.max((self.world.position(b) - root).length() / length.max(1e-6));
            }
        }
        worst
    }
}

/// An n-pendulum in rapier: fixed root at `root`, equal links along +x, no damping.
pub struct RapierPendulum {
    pub world: RapierWorld,
    bodies: Vec<RigidBodyHandle>,
    frame: u64,
    pub positions: Vec<DVec3>,
}

impl RapierPendulum {
    /// `joints` joints (so `joints - 1` links of `1 / (joints - 1)` m, 1 kg each) released straight out
    /// along +x from `root`.
    pub fn new(joints: usize, root: Vec3, solver: JointSolver) -> Self {
        let segment = 1.0 / (joints - 1) as f32;
        let positions: Vec<Vec3> = (0..joints).map(|i| root + Vec3::X * (segment * i as f32)).collect();
        let mut world = RapierWorld::new(solver);
        let bodies = world.add_chain(&positions, 1.0, 0.0, true);
        Self { world, bodies, frame: 0, positions: vec![DVec3::ZERO; joints] }
    }

    /// Steps one frame of `FRAME_DT` and reads every joint's position.
    pub fn frame(&mut self) {
        debug_assert!((self.world.params.dt - FRAME_DT).abs() < 1e-9);
        self.frame += 1;
        self.world.step();
        for (out, &b) in self.positions.iter_mut().zip(&self.bodies) {
            *out = self.world.position(b).as_dvec3();
        }
    }
}

/// RMS joint error / length of rapier's pendulum over the scenario (its bodies are at the call time).
pub fn rapier_error(reference: &Reference, solver: JointSolver) -> f64 {
    let mut run = RapierPendulum::new(reference.joints, ROOT, solver);
    let frames: Vec<Vec<DVec3>> = (0..Reference::frames())
        .map(|_| {
            run.frame();
            run.positions.clone()
        })
        .collect();
    rms_error(reference, &frames)
}
