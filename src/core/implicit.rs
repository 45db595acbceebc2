//! The exact projection onto the bond lengths, for the chains whose direct solve fails (bug 1 in
//! docs/robustness.md): Newton's method on the whole optimality system, positions and multipliers together.
//!
//! The projection moves the predicted positions `p` to the nearest `x` (unit masses, the root fixed) whose
//! bonds `b_k = x[k+1] - x[k]` have their rest lengths. At the answer, `x_j - p_j = mu_{j-1} b_{j-1} - mu_j
//! b_j`: the corrections act along the answer's own bonds, not the previous substep's (the direct solve) or
//! the current guess's (the Gauss-Newton projection). Both of those treat the bond directions explicitly, so
//! a tension wave that crosses more than about one segment per substep sends them astray. Newton on the full
//! system linearises the directions too: its matrix carries the tension's own stiffness (`mu` times the
//! chain's graph Laplacian), which is what turns a rope's tension into its sideways pull.
//!
//! Ordering the unknowns joint by joint, `(mu_{j-1}, x_j)`, makes that matrix block tridiagonal with 4 x 4
//! blocks, so each iteration is one block Thomas solve: O(n), with no pivoting across blocks, run from both
//! ends at once (see `newton_step`).
//!
//! Block `j` (joint `j`, `1 <= j <= m`) holds bond `j-1`'s constraint `c = (|b|^2 - l^2) / 2` and joint
//! `j`'s stationarity `s = x_j - p_j - mu_{j-1} b_{j-1} + mu_j b_j`. With `b = b_{j-1}`, `mu = mu_{j-1}`
//! and `t = 1 - mu_{j-1} - mu_j`, its Jacobian blocks are, by rows:
//! - on its own unknowns `(mu_{j-1}, x_j)`: `[0, b^T]` and `[-b, t I]`;
//! - on block `j-1`'s `(mu_{j-2}, x_{j-1})`: `[0, -b^T]` and `[0, mu I]`;
//! - on block `j+1`'s `(mu_j, x_{j+1})`: `[0, 0]` and `[b_j, mu_j I]`.
//!
//! The `mu` inside the position blocks (the multipliers' stiffness) count only where they pull (`mu < 0`,
//! tension): a pushing bond would make those blocks indefinite and the steps wild. That changes the steps,
//! not the equations solved, so the answer is the same exact projection.

use glam::{DMat3, DMat4, DVec3, DVec4};
use multiversion::multiversion;

/// Iterations before giving up (it converges quadratically once near; bug 1's fine rope takes a handful,
/// docs/robustness.md).
const MAX_ITERATIONS: usize = 24;
/// An error above this many times the start's (or than this, for a start below 1) means Newton has left the
/// basin it converges from (on its way it may overshoot by far less than that); Gauss-Seidel takes over.
const DIVERGED: f64 = 1e3;

/// Reusable buffers.
#[derive(Default)]
pub struct ImplicitScratch {
    /// One multiplier per bond.
    mu: Vec<f64>,
    /// The positions being projected (one per particle).
    target: Vec<DVec3>,
    /// Per block: the elimination's inverted pivot (by rows: column `i` is row `i`).
    pivots: Vec<DMat4>,
    /// Per block: the elimination's modified right-hand side, which the pass back reads.
    rhs: Vec<DVec4>,
    /// Per particle: the start's offset from the positions being projected (with `shifted`), and after a
    /// projection that converged, its answer's.
    correction: Vec<DVec3>,
    shifted: bool,
}

impl ImplicitScratch {
    pub fn reserve(&mut self, bonds: usize) {
        if self.mu.len() < bonds {
            self.mu.resize(bonds, 0.0);
            self.target.resize(bonds + 1, DVec3::ZERO);
            self.pivots.resize(bonds, DMat4::ZERO);
            self.rhs.resize(bonds, DVec4::ZERO);
            self.correction.resize(bonds + 1, DVec3::ZERO);
        }
    }
}

/// A multiplier where it pulls (negative), else 0. Written out rather than `f64::min`, whose result for
/// `-0.0` against `0.0` is left open, so that every compiled copy gives the same bits.
#[inline(always)]
fn pulling(mu: f64) -> f64 {
    if mu < 0.0 { mu } else { 0.0 }
}

/// Worst relative bond error `| |b|^2 / l^2 - 1 |` (NaN if any is).
#[inline(always)]
fn worst_error(p: &[DVec3], inv_l2: &[f64]) -> f64 {
    let mut worst = 0.0f64;
    for (k, inv) in inv_l2.iter().enumerate() {
        let error = ((p[k + 1] - p[k]).length_squared() * inv - 1.0).abs();
        if error.is_nan() || error > worst {
            worst = error;
        }
    }
    worst
}

/// The block above-diagonal `[[0, 0], [b, mu I]]` (by rows) times `u`.
#[inline(always)]
fn upper_times(b: DVec3, mu: f64, u: DVec4) -> DVec4 {
    DVec4::new(0.0, b.x * u.x + mu * u.y, b.y * u.x + mu * u.z, b.z * u.x + mu * u.w)
}

impl ImplicitScratch {
    /// Remembers the positions `p` to project and the start multipliers `guess`, with their compressions
    /// (and any that is not finite) dropped (a compressed bond can make the system indefinite). The direct solve's multipliers, even from
    /// a failed solve, are a good start for a rope's tensions.
    pub fn begin(&mut self, p: &[DVec3], guess: &[f64]) {
        let m = guess.len();
        self.reserve(m);
        self.target[..m + 1].copy_from_slice(&p[..m + 1]);
        for (mu, &g) in self.mu.iter_mut().zip(guess) {
            *mu = if g.is_finite() { pulling(g) } else { 0.0 };
        }
        self.shifted = false;
    }

    /// [`begin`](Self::begin), with Newton started from `p + shift` instead of `p` (one offset per particle;
    /// the first is ignored). The same chain's last correction is a good shift: from one substep to the next a
    /// rope's correction hardly changes, and from `p` alone its first bond errors are tens of percent (bug 1's
    /// fine rope, docs/robustness.md).
    pub fn begin_shifted(&mut self, p: &[DVec3], guess: &[f64], shift: &[DVec3]) {
        self.begin(p, guess);
        let m = guess.len();
        self.correction[..m + 1].copy_from_slice(&shift[..m + 1]);
        self.shifted = true;
    }
}

impl ImplicitScratch {
    /// The multipliers of the last projection, for a chain of `bonds` bonds.
    pub fn multipliers(&self, bonds: usize) -> &[f64] {
        &self.mu[..bonds]
    }

    /// The last converged projection's answer minus the positions it projected, per particle (the root's 0).
    pub fn correction(&self, bonds: usize) -> &[DVec3] {
        &self.correction[..bonds + 1]
    }
}

/// Projects the positions given to [`ImplicitScratch::begin`] (particle 0 fixed) onto the squared bond
/// lengths `l2` (`inv_l2` their reciprocals), into `p`, to within the relative error `tolerance` of
/// `|b|^2 / l^2 - 1`. Returns `false` when Newton fails; `p` then holds the positions given to `begin`.
#[multiversion(targets("x86_64+avx2"))]
pub fn project(p: &mut [DVec3], l2: &[f64], inv_l2: &[f64], tolerance: f64, s: &mut ImplicitScratch) -> bool {
    project_in(p, l2, inv_l2, tolerance, s).is_some()
}

/// [`project`] compiled for the baseline instruction set only, returning the Newton steps it took when it
/// converged: the tests check that both copies give the same bits (no fused or reordered operations), as the
/// lane kernels' copies do, and count steps.
#[cfg(test)]
pub fn project_portable(
    p: &mut [DVec3],
    l2: &[f64],
    inv_l2: &[f64],
    tolerance: f64,
    s: &mut ImplicitScratch,
) -> Option<usize> {
    project_in(p, l2, inv_l2, tolerance, s)
}

/// [`project`], returning the Newton steps taken when it converged.
#[inline(always)]
fn project_in(p: &mut [DVec3], l2: &[f64], inv_l2: &[f64], tolerance: f64, s: &mut ImplicitScratch) -> Option<usize> {
    let m = l2.len();
    let ImplicitScratch { mu, target, pivots, rhs, correction, shifted } = s;
    let (mu, target, pivots, rhs) = (&mut mu[..m], &target[..m + 1], &mut pivots[..m], &mut rhs[..m]);
    let (p, correction) = (&mut p[..m + 1], &mut correction[..m + 1]);
    p.copy_from_slice(target);
    if *shifted {
        for j in 1..=m {
            p[j] += correction[j];
        }
    }
    let mut limit = f64::NAN;
    for iteration in 0..MAX_ITERATIONS {
        let worst = worst_error(p, inv_l2);
        if worst <= tolerance {
            for j in 0..=m {
                correction[j] = p[j] - target[j];
            }
            return Some(iteration);
        }
        if iteration == 0 {
            limit = DIVERGED * worst.max(1.0);
        }
        if worst.is_nan() || worst >= limit {
            break;
        }
        if !newton_step(p, target, mu, l2, pivots, rhs) {
            break;
        }
    }
    p.copy_from_slice(target);
    None
}

/// One block's rows of the Newton system before elimination, and the bonds and stiffnesses that couple it to
/// its neighbours. Block `i` is joint `i + 1` with the multiplier of bond `i`.
struct Block {
    rows: [DVec4; 4],
    f: DVec4,
    /// Bond `i` and its multiplier's stiffness (the coupling to block `i - 1`).
    b_in: DVec3,
    k_in: f64,
    /// Bond `i + 1` and its stiffness (the coupling to block `i + 1`; zero at the tip).
    b_out: DVec3,
    k_out: f64,
}

#[inline(always)]
fn block(p: &[DVec3], target: &[DVec3], mu: &[f64], l2: &[f64], i: usize) -> Block {
    let m = l2.len();
    let b = p[i + 1] - p[i];
    let (b_after, mu_after) = if i + 1 < m { (p[i + 2] - p[i + 1], mu[i + 1]) } else { (DVec3::ZERO, 0.0) };
    // The stiffness of the pulling multipliers only (see the module documentation).
    let (k_in, k_out) = (pulling(mu[i]), pulling(mu_after));
    let t = 1.0 - k_in - k_out;
    let constraint = 0.5 * (b.length_squared() - l2[i]);
    let stationarity = p[i + 1] - target[i + 1] - mu[i] * b + mu_after * b_after;
    Block {
        // The block's own rows: [0, b^T] and [-b, t I].
        rows: [
            DVec4::new(0.0, b.x, b.y, b.z),
            DVec4::new(-b.x, t, 0.0, 0.0),
            DVec4::new(-b.y, 0.0, t, 0.0),
            DVec4::new(-b.z, 0.0, 0.0, t),
        ],
        f: -DVec4::new(constraint, stationarity.x, stationarity.y, stationarity.z),
        b_in: b,
        k_in,
        b_out: b_after,
        k_out,
    }
}

/// Eliminates the block before (`q` its inverted pivot, `y` its right-hand side) from `block`: subtracts
/// `L Q U` and `L Q y`, with `L = [[0, -b^T], [0, k I]]` and `U = [[0, 0], [b, k I]]` (bond `i`, both).
#[inline(always)]
fn eliminate_before(block: &mut Block, q: &DMat4, y: DVec4) {
    let (b, k) = (block.b_in, block.k_in);
    let (q1, q2, q3) = (q.y_axis, q.z_axis, q.w_axis);
    let w = [-(q1 * b.x + q2 * b.y + q3 * b.z), q1 * k, q2 * k, q3 * k];
    for (row, w) in block.rows.iter_mut().zip(w) {
        let wb = w.y * b.x + w.z * b.y + w.w * b.z;
        *row -= DVec4::new(wb, w.y * k, w.z * k, w.w * k);
    }
    block.f -= DVec4::new(w[0].dot(y), w[1].dot(y), w[2].dot(y), w[3].dot(y));
}

/// Eliminates the block after (`q` its inverted pivot, `z` its right-hand side) from `block`: subtracts
/// `U Q L` and `U Q z`, with `U = [[0, 0], [a, k I]]` and `L = [[0, -a^T], [0, k I]]` (bond `i + 1`, both).
#[inline(always)]
fn eliminate_after(block: &mut Block, q: &DMat4, z: DVec4) {
    let (a, k) = (block.b_out, block.k_out);
    let q0 = q.x_axis;
    let v = [q0 * a.x + q.y_axis * k, q0 * a.y + q.z_axis * k, q0 * a.z + q.w_axis * k];
    for (row, v) in block.rows[1..].iter_mut().zip(v) {
        let m = -a * v.x + DVec3::new(v.y, v.z, v.w) * k;
        *row -= DVec4::new(0.0, m.x, m.y, m.z);
    }
    let f = &mut block.f;
    (f.y, f.z, f.w) = (f.y - v[0].dot(z), f.z - v[1].dot(z), f.w - v[2].dot(z));
}

#[inline(always)]
fn times(q: &DMat4, v: DVec4) -> DVec4 {
    DVec4::new(q.x_axis.dot(v), q.y_axis.dot(v), q.z_axis.dot(v), q.w_axis.dot(v))
}

/// One Newton step: the block tridiagonal system solved from both ends at once (root to middle and tip to
/// middle, then outwards from the middle). Every block's elimination waits for its neighbour's inverse, so
/// one pass from the root is bound by that latency; two independent passes interleave and take about half
/// the time. Applies the step; returns `false` if it is not finite.
#[inline(always)]
fn newton_step(
    p: &mut [DVec3],
    target: &[DVec3],
    mu: &mut [f64],
    l2: &[f64],
    pivots: &mut [DMat4],
    rhs: &mut [DVec4],
) -> bool {
    let m = l2.len();
    // Blocks 0..middle from the root, middle + 1..m from the tip, the middle from both.
    let middle = m / 2;
    let (down, up) = (middle, m - 1 - middle);
    for s in 0..down.max(up) {
        if s < down {
            let mut b = block(p, target, mu, l2, s);
            if s > 0 {
                eliminate_before(&mut b, &pivots[s - 1], rhs[s - 1]);
            }
            pivots[s] = invert_bordered(&b.rows);
            rhs[s] = b.f;
        }
        if s < up {
            let i = m - 1 - s;
            let mut b = block(p, target, mu, l2, i);
            if i + 1 < m {
                eliminate_after(&mut b, &pivots[i + 1], rhs[i + 1]);
            }
            pivots[i] = invert_bordered(&b.rows);
            rhs[i] = b.f;
        }
    }
    let mut b = block(p, target, mu, l2, middle);
    if middle > 0 {
        eliminate_before(&mut b, &pivots[middle - 1], rhs[middle - 1]);
    }
    if middle + 1 < m {
        eliminate_after(&mut b, &pivots[middle + 1], rhs[middle + 1]);
    }
    let u = times(&invert_bordered(&b.rows), b.f);
    rhs[middle] = u;
    // Outwards; `rhs` takes each block's step, applied once every step is known (the couplings use the bonds
    // and multipliers as they were).
    let (mut below, mut above) = (u, u);
    for s in 1..=down.max(up) {
        if s <= down {
            let i = middle - s;
            let coupling = upper_times(p[i + 2] - p[i + 1], pulling(mu[i + 1]), below);
            below = times(&pivots[i], rhs[i] - coupling);
            rhs[i] = below;
        }
        if s <= up {
            let i = middle + s;
            let (b, k) = (p[i + 1] - p[i], pulling(mu[i]));
            let coupling =
                DVec4::new(-b.dot(DVec3::new(above.y, above.z, above.w)), k * above.y, k * above.z, k * above.w);
            above = times(&pivots[i], rhs[i] - coupling);
            rhs[i] = above;
        }
    }
    let mut finite = true;
    for i in 0..m {
        let u = rhs[i];
        finite &= u.is_finite();
        mu[i] += u.x;
        p[i + 1] += DVec3::new(u.y, u.z, u.w);
    }
    finite
}

/// The inverse, by rows (column `i` of the result is its row `i`), of the 4 x 4 matrix with rows `rows`,
/// through its lower right 3 x 3 block `M` (the position block, `t I` and a correction, far from singular)
/// and the Schur complement of `M`: a third of the instructions of a general 4 x 4 inverse, which took two
/// thirds of each iteration. Not finite when the matrix or `M` is singular.
#[inline(always)]
fn invert_bordered(rows: &[DVec4; 4]) -> DMat4 {
    let yzw = |v: DVec4| DVec3::new(v.y, v.z, v.w);
    let (corner, top) = (rows[0].x, yzw(rows[0]));
    let side = DVec3::new(rows[1].x, rows[2].x, rows[3].x);
    // Rows of M are columns of its transpose.
    let m_inverse_t = DMat3::from_cols(yzw(rows[1]), yzw(rows[2]), yzw(rows[3])).inverse();
    let m_inverse = m_inverse_t.transpose();
    let c = m_inverse * side;
    let a = m_inverse_t * top;
    let inv_schur = 1.0 / (corner - top.dot(c));
    let row = |c_i: f64, m_row: DVec3| {
        let r = m_row + a * (c_i * inv_schur);
        DVec4::new(-c_i * inv_schur, r.x, r.y, r.z)
    };
    DMat4::from_cols(
        DVec4::new(inv_schur, -a.x * inv_schur, -a.y * inv_schur, -a.z * inv_schur),
        row(c.x, m_inverse_t.x_axis),
        row(c.y, m_inverse_t.y_axis),
        row(c.z, m_inverse_t.z_axis),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bordered_inverse_is_the_inverse() {
        // A pivot as the elimination makes them: zero corner, a bond in the border, a position block near t I.
        let rows = [
            DVec4::new(-0.3, 1e-3, -2e-3, 5e-4),
            DVec4::new(-1e-3, 2.5, 0.1, -0.2),
            DVec4::new(2e-3, 0.05, 3.0, 0.3),
            DVec4::new(-5e-4, -0.1, 0.2, 2.0),
        ];
        let matrix = DMat4::from_cols(rows[0], rows[1], rows[2], rows[3]).transpose();
        let inverse = invert_bordered(&rows).transpose();
        let identity = matrix * inverse;
        assert!(identity.abs_diff_eq(DMat4::IDENTITY, 1e-12), "{identity}");
        let general = DMat4::from_cols(rows[0], rows[1], rows[2], rows[3]).inverse();
        assert!(
            invert_bordered(&rows)
                .abs_diff_eq(general, 1e-9 * general.abs().to_cols_array().iter().copied().fold(0.0, f64::max))
        );
    }
}
