//! Inextensibility: the chain's distance constraints solved together, the way molecular dynamics solves
//! rigid bonds (SHAKE). Corrections act along the bond directions of the previous substep, which keeps the
//! scheme symplectic and second order; the coupled system is tridiagonal, so a Newton iteration is one
//! O(n) Thomas solve.

use glam::DVec3;

/// Relative error of `|b|^2 / l^2 - 1` below which a bond counts as satisfied (about 5e-7 in length:
/// the float32 floor).
const TOLERANCE: f64 = 1e-9;
const MAX_NEWTON_ITERATIONS: usize = 8;
/// Largest error still accepted as a rounding floor when Newton stops improving.
const STAGNATION_LIMIT: f64 = 1e-3;
const FALLBACK_SWEEPS: usize = 64;

/// Reusable buffers, one entry per bond.
#[derive(Default)]
pub struct ConstraintScratch {
    lambda: Vec<f64>,
    bonds: Vec<DVec3>,
    directions: Vec<DVec3>,
    residual: Vec<f64>,
    diag: Vec<f64>,
    c_prime: Vec<f64>,
    d_prime: Vec<f64>,
}

impl ConstraintScratch {
    pub fn reserve(&mut self, bonds: usize) {
        for v in [&mut self.lambda, &mut self.residual, &mut self.diag, &mut self.c_prime, &mut self.d_prime] {
            if v.len() < bonds {
                v.resize(bonds, 0.0);
            }
        }
        if self.bonds.len() < bonds {
            self.bonds.resize(bonds, DVec3::ZERO);
            self.directions.resize(bonds, DVec3::ZERO);
        }
    }
}

/// Inverse mass of particle `j`: particle 0 is kinematic.
#[inline]
fn inv_mass<T: Default>(j: usize, dynamic_inv_mass: T) -> T {
    if j == 0 { T::default() } else { dynamic_inv_mass }
}

/// Moves `p` so that `|p[k+1] - p[k]| = lengths[k]` for every bond, correcting along the previous
/// positions' bonds `x[k+1] - x[k]`. Particle 0 never moves. Returns `false` when that direct solve failed
/// (a bond turned by about 90 degrees in one substep, as at the tip of a whipping rope) and the fallback
/// ran: the same Newton solve along the current bonds (always well conditioned, not symplectic), then, if
/// even that fails, Gauss-Seidel projection.
pub fn solve(x: &[DVec3], p: &mut [DVec3], lengths: &[f32], dynamic_inv_mass: f32, s: &mut ConstraintScratch) -> bool {
    let m = lengths.len();
    debug_assert!(x.len() == m + 1 && p.len() == m + 1);
    s.reserve(m);
    for k in 0..m {
        s.directions[k] = x[k + 1] - x[k];
    }
    if newton_along_directions(p, lengths, dynamic_inv_mass as f64, s) {
        return true;
    }
    for k in 0..m {
        s.directions[k] = p[k + 1] - p[k];
    }
    if !newton_along_directions(p, lengths, dynamic_inv_mass as f64, s) {
        project_gauss_seidel(p, lengths, dynamic_inv_mass);
    }
    false
}

/// Newton iterations on the multipliers of corrections along `s.directions` (one per bond); applies them
/// to `p` and returns `true` when converged, leaves `p` untouched otherwise.
fn newton_along_directions(p: &mut [DVec3], lengths: &[f32], dynamic_inv_mass: f64, s: &mut ConstraintScratch) -> bool {
    let m = lengths.len();
    let p = &mut p[..m + 1];
    let w = |j: usize| inv_mass(j, dynamic_inv_mass);
    let d = &s.directions[..m];
    let (lambda, bonds, residual) = (&mut s.lambda[..m], &mut s.bonds[..m], &mut s.residual[..m]);
    let (diag, c_prime, d_prime) = (&mut s.diag[..m], &mut s.c_prime[..m], &mut s.d_prime[..m]);
    lambda.fill(0.0);
    let mut converged = false;
    let mut previous_worst = f64::INFINITY;
    for _ in 0..MAX_NEWTON_ITERATIONS {
        // Bond vectors and residuals under the current multipliers, and the Jacobian's diagonal.
        let mut worst = 0.0f64;
        let mut scale = 0.0f64;
        for k in 0..m {
            let mut b = p[k + 1] - p[k] + d[k] * ((w(k) + w(k + 1)) * lambda[k]);
            if k > 0 {
                b -= d[k - 1] * (w(k) * lambda[k - 1]);
            }
            if k + 1 < m {
                b -= d[k + 1] * (w(k + 1) * lambda[k + 1]);
            }
            let l2 = lengths[k] as f64 * lengths[k] as f64;
            let f = b.length_squared() - l2;
            bonds[k] = b;
            residual[k] = -f;
            worst = worst.max((f / l2).abs());
            diag[k] = 2.0 * (w(k) + w(k + 1)) * b.dot(d[k]);
            scale = scale.max(diag[k].abs());
        }
        // Newton converges quadratically, so an iteration that fails to halve the error has reached the
        // rounding floor. (The system is solved in f64: its condition grows like n^2.)
        if worst <= TOLERANCE || (worst > 0.5 * previous_worst && worst < STAGNATION_LIMIT) {
            converged = true;
            break;
        }
        previous_worst = worst;
        if !thomas_solve(d, bonds, diag, residual, c_prime, d_prime, lambda, dynamic_inv_mass, scale) {
            break;
        }
    }
    if !converged {
        return false;
    }
    for j in 1..=m {
        let mut dp = d[j - 1] * lambda[j - 1];
        if j < m {
            dp -= d[j] * lambda[j];
        }
        p[j] += dp * w(j);
    }
    true
}

/// Solves the Newton system `J delta = residual` and adds `delta` to `lambda`. `J` is tridiagonal: its
/// diagonal is given (largest magnitude `scale`), its off-diagonal entries `d F_k / d lambda_(k-+1)` are
/// formed during the forward sweep. Returns `false` on a vanishing pivot or a non-finite result.
// `!(x > y)` on purpose: a NaN must fail the check too.
#[allow(clippy::neg_cmp_op_on_partial_ord, clippy::too_many_arguments)]
#[inline]
fn thomas_solve(
    d: &[DVec3],
    bonds: &[DVec3],
    diag: &[f64],
    residual: &[f64],
    c_prime: &mut [f64],
    d_prime: &mut [f64],
    lambda: &mut [f64],
    dynamic_inv_mass: f64,
    scale: f64,
) -> bool {
    let m = lambda.len();
    let (d, bonds, diag, residual) = (&d[..m], &bonds[..m], &diag[..m], &residual[..m]);
    let (c_prime, d_prime) = (&mut c_prime[..m], &mut d_prime[..m]);
    let w = |j: usize| inv_mass(j, dynamic_inv_mass);
    let tiny = scale * 1e-7;
    if !(scale > 0.0) {
        return false;
    }
    // Forward elimination; one division per row.
    let (mut c_last, mut d_last) = (0.0f64, 0.0f64);
    for k in 0..m {
        let b = bonds[k];
        let lower = if k > 0 { -2.0 * w(k) * b.dot(d[k - 1]) } else { 0.0 };
        let upper = if k + 1 < m { -2.0 * w(k + 1) * b.dot(d[k + 1]) } else { 0.0 };
        let den = diag[k] - lower * c_last;
        if !(den.abs() > tiny) {
            return false;
        }
        let inv = 1.0 / den;
        c_last = upper * inv;
        d_last = (residual[k] - lower * d_last) * inv;
        c_prime[k] = c_last;
        d_prime[k] = d_last;
    }
    let mut next = 0.0f64;
    for k in (0..m).rev() {
        let delta = d_prime[k] - c_prime[k] * next;
        if !delta.is_finite() {
            return false;
        }
        lambda[k] += delta;
        next = delta;
    }
    true
}

/// Classic position-based projection along the current bonds: always well defined, slow to converge on
/// long chains. Only used when the direct solve fails.
fn project_gauss_seidel(p: &mut [DVec3], lengths: &[f32], dynamic_inv_mass: f32) {
    let dynamic_inv_mass = dynamic_inv_mass as f64;
    for _ in 0..FALLBACK_SWEEPS {
        for (k, &rest) in lengths.iter().enumerate() {
            let (wa, wb) = (inv_mass(k, dynamic_inv_mass), inv_mass(k + 1, dynamic_inv_mass));
            let delta = p[k + 1] - p[k];
            let len = delta.length();
            if len <= f64::MIN_POSITIVE || wa + wb == 0.0 {
                continue;
            }
            let correction = delta * ((len - rest as f64) / (len * (wa + wb)));
            p[k] += correction * wa;
            p[k + 1] -= correction * wb;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn max_stretch(p: &[DVec3], lengths: &[f32]) -> f64 {
        lengths
            .iter()
            .enumerate()
            .map(|(k, l)| ((p[k + 1] - p[k]).length() / *l as f64 - 1.0).abs())
            .fold(0.0, f64::max)
    }

    fn line(n: usize, spacing: f64) -> Vec<DVec3> {
        (0..n).map(|i| DVec3::new(spacing * i as f64, 0.0, 0.0)).collect()
    }

    #[test]
    fn restores_lengths_after_a_small_step() {
        let x = line(9, 0.1);
        let lengths = vec![0.1; 8];
        // Gravity drop of one 240 Hz step on every dynamic particle.
        let mut p: Vec<DVec3> =
            x.iter().enumerate().map(|(i, v)| if i == 0 { *v } else { *v - DVec3::Y * 1.7e-4 }).collect();
        let mut s = ConstraintScratch::default();
        assert!(solve(&x, &mut p, &lengths, 1.0, &mut s));
        assert!(max_stretch(&p, &lengths) < 1e-6, "{}", max_stretch(&p, &lengths));
        assert_eq!(p[0], x[0]);
    }

    #[test]
    fn long_chain_converges() {
        let x = line(1000, 0.01);
        let lengths = vec![0.01; 999];
        let mut p: Vec<DVec3> = x
            .iter()
            .enumerate()
            .map(|(i, v)| *v + DVec3::new(0.0, -1e-4 * (i as f64).sqrt(), 2e-5 * (i % 3) as f64))
            .collect();
        p[0] = x[0];
        let mut s = ConstraintScratch::default();
        assert!(solve(&x, &mut p, &lengths, 1.0, &mut s));
        assert!(max_stretch(&p, &lengths) < 1e-6, "{}", max_stretch(&p, &lengths));
    }

    #[test]
    fn folded_chain_falls_back_and_stays_finite() {
        // Previous bonds perpendicular to the target bonds: the direct solve has no purchase.
        let x = vec![DVec3::ZERO, DVec3::X, DVec3::new(2.0, 0.0, 0.0)];
        let mut p = vec![DVec3::ZERO, DVec3::new(0.0, 3.0, 0.0), DVec3::new(0.0, 3.0, 2.0)];
        let mut s = ConstraintScratch::default();
        assert!(!solve(&x, &mut p, &[1.0, 1.0], 1.0, &mut s));
        assert!(p.iter().all(|v| v.is_finite()));
        assert!(max_stretch(&p, &[1.0, 1.0]) < 1e-3);
    }
}
