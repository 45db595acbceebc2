//! Inextensibility: the chain's distance constraints solved together, the way molecular dynamics solves
//! rigid bonds (SHAKE). Corrections act along the bond directions of the previous substep, which keeps the
//! scheme symplectic and second order; the coupled system is tridiagonal, so a Newton iteration is one
//! O(n) Thomas solve.

use glam::{DVec3, Vec3};

/// Relative error of `|b|^2 / l^2 - 1` below which a bond counts as satisfied (about 5e-7 in length:
/// the float32 floor).
const TOLERANCE: f32 = 1e-6;
const MAX_NEWTON_ITERATIONS: usize = 8;
/// Largest error still accepted as a rounding floor when Newton stops improving.
const STAGNATION_LIMIT: f32 = 1e-3;
const FALLBACK_SWEEPS: usize = 64;

/// Reusable buffers, one entry per bond.
#[derive(Default)]
pub struct ConstraintScratch {
    lambda: Vec<f32>,
    bonds: Vec<Vec3>,
    residual: Vec<f32>,
    diag: Vec<f32>,
    lower: Vec<f32>,
    upper: Vec<f32>,
    c_prime: Vec<f32>,
    d_prime: Vec<f32>,
}

impl ConstraintScratch {
    pub fn reserve(&mut self, bonds: usize) {
        for v in [
            &mut self.lambda,
            &mut self.residual,
            &mut self.diag,
            &mut self.lower,
            &mut self.upper,
            &mut self.c_prime,
            &mut self.d_prime,
        ] {
            if v.len() < bonds {
                v.resize(bonds, 0.0);
            }
        }
        if self.bonds.len() < bonds {
            self.bonds.resize(bonds, Vec3::ZERO);
        }
    }
}

/// Inverse mass of particle `j`: particle 0 is kinematic.
#[inline]
fn inv_mass<T: Default>(j: usize, dynamic_inv_mass: T) -> T {
    if j == 0 { T::default() } else { dynamic_inv_mass }
}

/// Moves `p` so that `|p[k+1] - p[k]| = lengths[k]` for every bond, correcting along the previous
/// positions' bonds `x[k+1] - x[k]`. Particle 0 never moves. Returns `false` when the direct solve failed
/// (a bond turned by about 90 degrees in one substep) and a Gauss-Seidel fallback along current bonds was
/// used instead.
pub fn solve(x: &[DVec3], p: &mut [DVec3], lengths: &[f32], dynamic_inv_mass: f32, s: &mut ConstraintScratch) -> bool {
    let m = lengths.len();
    debug_assert!(x.len() == m + 1 && p.len() == m + 1);
    s.reserve(m);
    let w = |j: usize| inv_mass(j, dynamic_inv_mass);
    let d = |k: usize| (x[k + 1] - x[k]).as_vec3();
    s.lambda[..m].fill(0.0);

    let mut converged = false;
    let mut previous_worst = f32::INFINITY;
    for _ in 0..MAX_NEWTON_ITERATIONS {
        // Bond vectors and residuals under the current multipliers.
        let mut worst = 0.0f32;
        for k in 0..m {
            let mut b = (p[k + 1] - p[k]).as_vec3() + d(k) * ((w(k) + w(k + 1)) * s.lambda[k]);
            if k > 0 {
                b -= d(k - 1) * (w(k) * s.lambda[k - 1]);
            }
            if k + 1 < m {
                b -= d(k + 1) * (w(k + 1) * s.lambda[k + 1]);
            }
            let l2 = lengths[k] * lengths[k];
            let f = b.length_squared() - l2;
            s.bonds[k] = b;
            s.residual[k] = -f;
            worst = worst.max((f / l2).abs());
        }
        // Newton converges quadratically, so an iteration that fails to halve the error has reached the
        // rounding floor of float32 positions (which grows with the distance from the origin).
        if worst <= TOLERANCE || (worst > 0.5 * previous_worst && worst < STAGNATION_LIMIT) {
            converged = true;
            break;
        }
        previous_worst = worst;
        // Jacobian of F_k = |b_k|^2 - l_k^2 with respect to the multipliers: tridiagonal.
        for k in 0..m {
            let b = s.bonds[k];
            s.diag[k] = 2.0 * (w(k) + w(k + 1)) * b.dot(d(k));
            s.lower[k] = if k > 0 { -2.0 * w(k) * b.dot(d(k - 1)) } else { 0.0 };
            s.upper[k] = if k + 1 < m { -2.0 * w(k + 1) * b.dot(d(k + 1)) } else { 0.0 };
        }
        if !thomas_solve(s, m) {
            break;
        }
    }
    if converged {
        for j in 1..=m {
            let mut dp = Vec3::ZERO;
            dp += d(j - 1) * s.lambda[j - 1];
            if j < m {
                dp -= d(j) * s.lambda[j];
            }
            p[j] += (dp * w(j)).as_dvec3();
        }
        return true;
    }
    project_gauss_seidel(p, lengths, dynamic_inv_mass);
    false
}

/// Solves the tridiagonal system in `s` (diag, lower, upper, residual as right-hand side) and adds the
/// solution to `s.lambda`. Returns `false` on a vanishing pivot or a non-finite result.
// `!(x > y)` on purpose: a NaN must fail the check too.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn thomas_solve(s: &mut ConstraintScratch, m: usize) -> bool {
    let scale = s.diag[..m].iter().fold(0.0f32, |a, b| a.max(b.abs()));
    let tiny = scale * 1e-7;
    if !(scale > 0.0) || !(s.diag[0].abs() > tiny) {
        return false;
    }
    s.c_prime[0] = s.upper[0] / s.diag[0];
    s.d_prime[0] = s.residual[0] / s.diag[0];
    for k in 1..m {
        let den = s.diag[k] - s.lower[k] * s.c_prime[k - 1];
        if !(den.abs() > tiny) {
            return false;
        }
        s.c_prime[k] = s.upper[k] / den;
        s.d_prime[k] = (s.residual[k] - s.lower[k] * s.d_prime[k - 1]) / den;
    }
    let mut next = 0.0f32;
    for k in (0..m).rev() {
        let delta = s.d_prime[k] - s.c_prime[k] * next;
        if !delta.is_finite() {
            return false;
        }
        s.lambda[k] += delta;
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
