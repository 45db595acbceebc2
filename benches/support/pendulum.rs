//! Exact reference for the n-pendulum: point masses on rigid massless links, in reduced coordinates (one
//! angle per link), double precision, integrated by an adaptive Dormand–Prince 5(4) method that steps
//! exactly onto every requested output time (no interpolation error).
//!
//! The model is planar (the x-y plane, gravity and root motion in that plane). The accuracy scenarios
//! start the chain in that plane at rest, with gravity and any root motion in it, so by symmetry the
//! exact motion never leaves it: the out-of-plane equations are satisfied identically by zero. A 3D
//! model would integrate the same trajectory with twice the unknowns and a gimbal-free parametrisation.
//!
//! Link `k` (0-based) joins joint `k` to joint `k + 1`; its direction is `u_k = (sin θ_k, -cos θ_k)`
//! (θ = 0 hangs straight down, θ = π/2 points along +x). Joint 0 is the root, prescribed as a function of
//! time; joints `1..=n` carry the masses. With `μ_k = Σ_{i > k} m_i` (the mass beyond link `k`) the
//! equations of motion (Lagrange) are
//!
//! ```text
//! Σ_k μ_max(j,k) l_j l_k [cos(θ_j - θ_k) θ̈_k + sin(θ_j - θ_k) θ̇_k²] = μ_j l_j (g_x cos θ_j + g_y sin θ_j)
//! ```
//!
//! where `g = gravity - root acceleration` (in the root's translating frame the root's acceleration acts
//! as extra uniform gravity). The mass matrix is symmetric positive definite and is factorised (Cholesky)
//! at every evaluation.
#![allow(dead_code)]
// Numerical kernels index several parallel arrays (stages, state components) with one index.
#![allow(clippy::needless_range_loop)]

/// Root position, velocity and acceleration at a time (planar, m, m/s, m/s²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RootMotion {
    pub position: [f64; 2],
    pub velocity: [f64; 2],
    pub acceleration: [f64; 2],
}

impl RootMotion {
    pub const fn fixed(position: [f64; 2]) -> Self {
        Self { position, velocity: [0.0; 2], acceleration: [0.0; 2] }
    }
}

/// A planar n-pendulum with a prescribed root trajectory.
pub struct Pendulum {
    /// Link lengths, m.
    pub lengths: Vec<f64>,
    /// Masses of joints `1..=n` (one per link, at the link's far end), kg.
    pub masses: Vec<f64>,
    /// Gravity, m/s² (planar).
    pub gravity: [f64; 2],
    /// The root trajectory.
    pub root: Box<dyn Fn(f64) -> RootMotion>,
    /// `μ_k`: total mass beyond link `k`.
    beyond: Vec<f64>,
}

/// Integrator tolerances (relative and absolute, per state component: radians and rad/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    pub relative: f64,
    pub absolute: f64,
}

impl Tolerance {
    /// Tight enough that the joint positions are accurate to far better than 1e-10 m over the scenarios'
    /// 0.5 s (checked in `tests/reference.rs` against a tolerance 100 times tighter).
    pub const REFERENCE: Self = Self { relative: 1e-13, absolute: 1e-13 };
}

/// Work done by one integration, for reports.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Work {
    pub accepted: u64,
    pub rejected: u64,
    pub evaluations: u64,
}

impl Pendulum {
    /// Equal links of `length` and equal `mass`es under `gravity`, root fixed at the origin.
    pub fn uniform(links: usize, length: f64, mass: f64, gravity: [f64; 2]) -> Self {
        Self::new(vec![length; links], vec![mass; links], gravity, Box::new(|_| RootMotion::fixed([0.0; 2])))
    }

    pub fn new(lengths: Vec<f64>, masses: Vec<f64>, gravity: [f64; 2], root: Box<dyn Fn(f64) -> RootMotion>) -> Self {
        assert_eq!(lengths.len(), masses.len(), "one mass per link");
        assert!(!lengths.is_empty(), "at least one link");
        let n = lengths.len();
        let mut beyond = vec![0.0; n];
        let mut sum = 0.0;
        for k in (0..n).rev() {
            sum += masses[k];
            beyond[k] = sum;
        }
        Self { lengths, masses, gravity, root, beyond }
    }

    pub fn links(&self) -> usize {
        self.lengths.len()
    }

    /// The state `[θ_0..θ_{n-1}, θ̇_0..θ̇_{n-1}]` with every link at `angle`, at rest.
    pub fn state_at_rest(&self, angles: &[f64]) -> Vec<f64> {
        assert_eq!(angles.len(), self.links());
        let mut y = angles.to_vec();
        y.resize(2 * self.links(), 0.0);
        y
    }

    /// Joint positions (root first) for state `y` at time `t`.
    pub fn positions(&self, t: f64, y: &[f64]) -> Vec<[f64; 2]> {
        let mut p = (self.root)(t).position;
        let mut out = Vec::with_capacity(self.links() + 1);
        out.push(p);
        for k in 0..self.links() {
            let (s, c) = y[k].sin_cos();
            p = [p[0] + self.lengths[k] * s, p[1] - self.lengths[k] * c];
            out.push(p);
        }
        out
    }

    /// Total mechanical energy (kinetic + gravitational potential, zero at the root's height), J. Exact
    /// invariant only for a root at rest.
    pub fn energy(&self, t: f64, y: &[f64]) -> f64 {
        let n = self.links();
        let root = (self.root)(t);
        let mut kinetic = 0.0;
        let mut velocity = root.velocity;
        let mut potential = 0.0;
        let mut p = root.position;
        for k in 0..n {
            let (s, c) = y[k].sin_cos();
            let l = self.lengths[k];
            velocity = [velocity[0] + l * c * y[n + k], velocity[1] + l * s * y[n + k]];
            p = [p[0] + l * s, p[1] - l * c];
            let m = self.masses[k];
            kinetic += 0.5 * m * (velocity[0] * velocity[0] + velocity[1] * velocity[1]);
            potential -= m * (self.gravity[0] * p[0] + self.gravity[1] * p[1]);
        }
        kinetic + potential
    }

    /// `dy/dt` at `(t, y)` into `dy`; `scratch` holds the n×n system.
    fn derivative(&self, t: f64, y: &[f64], dy: &mut [f64], scratch: &mut Vec<f64>) {
        let n = self.links();
        let a = (self.root)(t).acceleration;
        let g = [self.gravity[0] - a[0], self.gravity[1] - a[1]];
        scratch.clear();
        scratch.resize(n * n + n, 0.0);
        let (m, b) = scratch.split_at_mut(n * n);
        let (theta, omega) = y.split_at(n);
        for j in 0..n {
            let (sj, cj) = theta[j].sin_cos();
            let lj = self.lengths[j];
            let mut rhs = self.beyond[j] * lj * (g[0] * cj + g[1] * sj);
            for k in 0..n {
                let coupling = self.beyond[j.max(k)] * lj * self.lengths[k];
                let (s, c) = (theta[j] - theta[k]).sin_cos();
                m[j * n + k] = coupling * c;
                rhs -= coupling * s * omega[k] * omega[k];
            }
            b[j] = rhs;
        }
        cholesky_solve(m, b, n);
        dy[..n].copy_from_slice(omega);
        dy[n..].copy_from_slice(b);
    }

    /// Integrates from state `y0` at `t0` and returns the state at each of `times` (ascending, >= t0).
    pub fn solve(&self, t0: f64, y0: &[f64], times: &[f64], tolerance: Tolerance) -> (Vec<Vec<f64>>, Work) {
        let mut out = Vec::with_capacity(times.len());
        let mut y = y0.to_vec();
        let mut t = t0;
        let mut work = Work::default();
        let mut integrator = Dopri5::new(y.len());
        let mut h = 1e-4;
        for &target in times {
            assert!(target >= t, "output times must be ascending and not before t0");
            while t < target {
                let remaining = target - t;
                // Land exactly on the output time; avoid a sliver step just before it.
                let (step, lands) = if h >= remaining * (1.0 - 1e-12) {
                    (remaining, true)
                } else if h > 0.5 * remaining {
                    (0.5 * remaining, false)
                } else {
                    (h, false)
                };
                let (accepted, suggestion) = integrator.step(self, t, &mut y, step, tolerance, &mut work);
                if accepted {
                    t = if lands { target } else { t + step };
                    // Keep the step the controller wants, not the shortened one that hit the output.
                    h = if lands { suggestion.max(h) } else { suggestion };
                } else {
                    h = suggestion;
                }
                assert!(h > 1e-14, "step size underflow at t = {t}");
            }
            out.push(y.clone());
        }
        (out, work)
    }

    /// The state at `t1` from `y0` at `t0`.
    pub fn advance(&self, t0: f64, y0: &[f64], t1: f64, tolerance: Tolerance) -> Vec<f64> {
        self.solve(t0, y0, &[t1], tolerance).0.pop().expect("one output")
    }
}

/// Solves `m x = b` in place (`b` becomes `x`) for symmetric positive definite `m` (n×n, row major).
fn cholesky_solve(m: &mut [f64], b: &mut [f64], n: usize) {
    // Lower factor L in the lower triangle of m.
    for j in 0..n {
        let mut d = m[j * n + j];
        for k in 0..j {
            d -= m[j * n + k] * m[j * n + k];
        }
        assert!(d > 0.0, "mass matrix not positive definite");
        let d = d.sqrt();
        m[j * n + j] = d;
        for i in j + 1..n {
            let mut s = m[i * n + j];
            for k in 0..j {
                s -= m[i * n + k] * m[j * n + k];
            }
            m[i * n + j] = s / d;
        }
    }
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= m[i * n + k] * b[k];
        }
        b[i] = s / m[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= m[k * n + i] * b[k];
        }
        b[i] = s / m[i * n + i];
    }
}

/// Dormand–Prince 5(4) (Dormand & Prince 1980; Hairer, Nørsett & Wanner, "Solving ODEs I", II.5), with
/// the standard error norm and step controller.
struct Dopri5 {
    k: [Vec<f64>; 7],
    stage: Vec<f64>,
    next: Vec<f64>,
    scratch: Vec<f64>,
    /// First-same-as-last: `k[0]` holds the derivative at the current state.
    fresh: bool,
}

const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0],
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0],
    [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0],
];
/// Fifth-order weights (= the last row of A) minus the embedded fourth-order ones.
const E: [f64; 7] =
    [71.0 / 57600.0, 0.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0];

impl Dopri5 {
    fn new(n: usize) -> Self {
        Self {
            k: std::array::from_fn(|_| vec![0.0; n]),
            stage: vec![0.0; n],
            next: vec![0.0; n],
            scratch: Vec::new(),
            fresh: false,
        }
    }

    /// Tries one step of `h` from `(t, y)`. On acceptance `y` is advanced. Returns (accepted, next h).
    fn step(
        &mut self,
        system: &Pendulum,
        t: f64,
        y: &mut [f64],
        h: f64,
        tolerance: Tolerance,
        work: &mut Work,
    ) -> (bool, f64) {
        let n = y.len();
        if !self.fresh {
            system.derivative(t, y, &mut self.k[0], &mut self.scratch);
            work.evaluations += 1;
            self.fresh = true;
        }
        for s in 1..7 {
            for i in 0..n {
                let mut sum = 0.0;
                for (j, a) in A[s][..s].iter().enumerate() {
                    sum += a * self.k[j][i];
                }
                self.stage[i] = y[i] + h * sum;
            }
            let (_, rest) = self.k.split_at_mut(s);
            system.derivative(t + C[s] * h, &self.stage, &mut rest[0], &mut self.scratch);
            work.evaluations += 1;
        }
        // Stage 7 was evaluated at the fifth-order solution: that is the new state.
        self.next.copy_from_slice(&self.stage);
        let mut norm = 0.0;
        for i in 0..n {
            let mut e = 0.0;
            for (s, weight) in E.iter().enumerate() {
                e += weight * self.k[s][i];
            }
            let scale = tolerance.absolute + tolerance.relative * y[i].abs().max(self.next[i].abs());
            norm += (h * e / scale).powi(2);
        }
        let err = (norm / n as f64).sqrt();
        let factor = if err == 0.0 { 5.0 } else { (0.9 * err.powf(-0.2)).clamp(0.2, 5.0) };
        if err <= 1.0 {
            y.copy_from_slice(&self.next);
            self.k.swap(0, 6);
            work.accepted += 1;
            (true, h * factor)
        } else {
            work.rejected += 1;
            (false, h * factor.min(1.0))
        }
    }
}

/// The exact period of a single pendulum of length `l` released at
/// rest from amplitude `theta0`, `T = 2π sqrt(l/g) / AGM(1, cos(θ0/2))`.
pub fn exact_single_period(length: f64, gravity: f64, theta0: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (0.5 * theta0).cos());
    // Quadratic convergence: a handful of iterations reach the last bit (a fixed count cannot cycle on it).
    for _ in 0..40 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    2.0 * std::f64::consts::PI * (length / gravity).sqrt() / a
}
