//! Rotation part of a 3x3 matrix, after Müller et al. 2016, "A Robust Method to Extract the Rotational
//! Part of Deformations": iterate a quaternion towards the rotation that best aligns its columns with the
//! matrix's, warm-started from the previous step's answer. Unlike SVD-based polar decomposition it never
//! flips on reflections and degrades gracefully for rank-deficient matrices (two-particle groups).
//!
//! Müller's step is a gradient step on `tr(R^T A)` scaled by the trace; it converges linearly, slowly in the
//! directions where `A` is thin (a rod group's twist). Where the local Hessian is safely positive definite
//! the step here is the Newton step instead (same fixed point, quadratic convergence), so a warm start
//! reaches float precision in one or two steps; elsewhere (far from the answer, rank-deficient matrices) it
//! is Müller's step unchanged. Everything is evaluated in the current rotation's frame, `S = R^T A`.
//!
//! A step `e` (a rotation vector) turns the quaternion by the Cayley map of `e` (`turn`) rather than by its
//! exponential: the same rotation to second order, so the Newton step keeps its quadratic convergence, with no
//! series in the iteration's chain of dependent operations, whose latency sets its time.

use glam::{Mat3A, Quat, Vec3};

/// Rotation updates below this (radians) change nothing at float32 precision.
pub(crate) const CONVERGED_ANGLE: f32 = 1e-7;
/// Newton steps longer than this (radians) are not trusted: the quadratic model is local.
pub(crate) const MAX_NEWTON_ANGLE: f32 = 0.5;
/// A Newton step shorter than this (radians) is the last: the error it leaves, about a twentieth of its
/// square, is a few float32 roundings of a unit quaternion (`a_landed_newton_step_leaves_only_rounding`).
/// Testing convergence after it instead would compare a gradient that float32 rounding alone keeps near
/// `CONVERGED_ANGLE`, and the lane solver iterates until its last lane passes that. Landing sooner saves a pass
/// of the loop for most groups of a moving chain (the lane solver runs one for all its lanes while any one
/// needs it): at 1e-4, its value until this was measured, `valgrind --tool=callgrind
/// target/release/examples/step_cost 64 16 20 sway` counted 17.2M instructions in `polar8`, here 14.0M (with
/// `inextensible::TOLERANCE` raised in the same commit, 49a58a2). Landing later still leaves errors that a
/// rounding difference between the lane and scalar solvers switches on and off (at 1e-2, `tests/lanes.rs`
/// then counts more contact pairs on one solver than its bound allows).
pub(crate) const LANDING_ANGLE: f32 = 3e-3;
/// [`LANDING_ANGLE`] of a shape-matching pass that another pass of the same substep follows. Its last Newton
/// step leaves an error that shrinks with the step's square (`a_rough_pass_leaves_what_the_polishing_pass_removes`:
/// up to a quarter of it), and the next pass, warm-started from this pass's rotations, takes that out with its
/// own steps: only the substep's last pass must end at float rounding. With two passes per substep, the first
/// starts a substep's motion away from the last substep's answer, and its groups took a second Newton step
/// about as often as not (the lane solver takes one for all its lanes while any one needs it); landing them
/// after the first cut the polar decomposition's instructions by a quarter (`docs/performance-history.md`,
/// stop 31). Unlike a later landing in every pass (above), the lane and scalar solvers' contact-pair counts stay
/// within the bound of `tests/lanes.rs`: the last pass's rotations, which the substep's positions keep, are
/// polished as before.
pub(crate) const ROUGH_LANDING_ANGLE: f32 = 1e-1;
/// Relative size of the Hessian's smallest pivot below which it counts as singular.
pub(crate) const MIN_PIVOT: f32 = 1e-4;
/// Steps longer than this (radians) turn by the exact exponential instead of the Cayley map ([`turn`]): the
/// longest Newton step, so only Müller's steps far from the answer do.
pub(crate) const LONG_TURN: f32 = MAX_NEWTON_ANGLE;

/// The landing angle of shape-matching pass `pass` of `passes` in a substep: only the last one polishes.
#[inline]
pub(crate) fn landing_angle(pass: u32, passes: u32) -> f32 {
    if pass + 1 < passes { ROUGH_LANDING_ANGLE } else { LANDING_ANGLE }
}

/// Improves `q` in place towards the rotation part of `a`, for at most `max_iterations` iterations or until a
/// Newton step shorter than `landing` (radians: [`landing_angle`]). Returns
/// the rotation matrix of the final `q` (the convergence test has usually just computed it).
#[inline]
pub fn extract_rotation(a: &Mat3A, q: &mut Quat, max_iterations: u32, landing: f32) -> Mat3A {
    // The guard against a vanishing denominator scales with the matrix, so a millimetre-sized chain (entries
    // ~1e-7) is treated exactly like a metre-sized one.
    let guard = 1e-9 * (a.x_axis.length_squared() + a.y_axis.length_squared() + a.z_axis.length_squared()).sqrt()
        + f32::MIN_POSITIVE;
    for _ in 0..max_iterations {
        let r = Mat3A::from_quat(*q);
        // Columns of `S = R^T A`: `s.col(c)[r] = r_r . a_c`.
        let s = r.transpose() * *a;
        // Gradient of `tr(R^T A)` over a rotation `R exp([e])`, in the frame of `R`: the axial vector of
        // `S - S^T`, equal to `R^T sum_i r_i x a_i` of Müller's formulation.
        let g = Vec3::new(s.y_axis.z - s.z_axis.y, s.z_axis.x - s.x_axis.z, s.x_axis.y - s.y_axis.x);
        let trace = s.x_axis.x + s.y_axis.y + s.z_axis.z;
        let muller = g / (trace.abs() + guard);
        if muller.length_squared() < CONVERGED_ANGLE * CONVERGED_ANGLE {
            return r;
        }
        let newton = newton_step(&s, g, trace);
        *q = (*q * turn(newton.unwrap_or(muller))).normalize();
        if newton.is_some_and(|step| step.length_squared() < landing * landing) {
            break;
        }
    }
    Mat3A::from_quat(*q)
}

/// The Newton step `H^-1 g` with `H = tr(S) I - sym(S)` (the Hessian of `-tr(R^T A)`), if `H` is safely
/// positive definite and the step short.
#[inline]
fn newton_step(s: &Mat3A, g: Vec3, trace: f32) -> Option<Vec3> {
    let (h00, h11, h22) = (trace - s.x_axis.x, trace - s.y_axis.y, trace - s.z_axis.z);
    let h01 = -0.5 * (s.y_axis.x + s.x_axis.y);
    let h02 = -0.5 * (s.z_axis.x + s.x_axis.z);
    let h12 = -0.5 * (s.z_axis.y + s.y_axis.z);
    // Cofactors of the symmetric H; positive definite iff the leading minors are positive.
    let c00 = h11 * h22 - h12 * h12;
    let c01 = h02 * h12 - h01 * h22;
    let c02 = h01 * h12 - h02 * h11;
    let c11 = h00 * h22 - h02 * h02;
    let c12 = h01 * h02 - h00 * h12;
    let c22 = h00 * h11 - h01 * h01;
    let det = h00 * c00 + h01 * c01 + h02 * c02;
    let scale = trace.abs();
    let pivot = MIN_PIVOT * scale;
    // `!(x > y)` would also reject NaN; `x > y` is false for NaN, so these conditions do.
    if !(h00 > pivot && c22 > pivot * pivot && det > pivot * pivot * pivot) {
        return None;
    }
    let inv_det = 1.0 / det;
    let step = Vec3::new(
        c00 * g.x + c01 * g.y + c02 * g.z,
        c01 * g.x + c11 * g.y + c12 * g.z,
        c02 * g.x + c12 * g.y + c22 * g.z,
    ) * inv_det;
    (step.length_squared() <= MAX_NEWTON_ANGLE * MAX_NEWTON_ANGLE).then_some(step)
}

/// The turn by the rotation vector `e`: the Cayley map `(e / 2, 1)` up to `LONG_TURN`, the exponential beyond;
/// not normalised (the caller normalises the product).
///
/// Normalised, the Cayley map turns about `e` by `2 atan(|e| / 2) = |e| - |e|^3 / 12 + ...`: at a landing step
/// (`LANDING_ANGLE`) 2e-9 radians short of the exponential's turn, far below what the step itself leaves; a
/// longer step falls short by more (2 % at `LONG_TURN`) and the next iteration takes the rest. Beyond
/// `LONG_TURN` the map saturates towards half a turn, and Müller's steps on a rank-1 matrix a quarter turn away
/// can then alternate between two rotations for ever (`rank_deficient_matrix_stays_finite`); the exponential's
/// turn by the step's whole length breaks that symmetry.
///
/// Against the exponential's series (`math::exp_small`) this takes the series out of the iteration's chain of
/// dependent operations: on the lane solver's iteration, 105.5 against 136 cycles of `llvm-mca -mcpu=znver3`
/// (`tools/instruction_mix.py --body`, `docs/performance-history.md`).
#[inline]
fn turn(e: Vec3) -> Quat {
    if e.length_squared() > LONG_TURN * LONG_TURN {
        return Quat::from_scaled_axis(e);
    }
    Quat::from_xyzw(0.5 * e.x, 0.5 * e.y, 0.5 * e.z, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::math::rotation_angle;
    use crate::core::rod::POLAR_ITERATIONS;
    use glam::{Vec3, Vec3A};

    #[test]
    fn recovers_rotation_of_stretched_matrix() {
        let truth = Quat::from_euler(glam::EulerRot::YXZ, 0.8, -0.4, 1.9);
        let stretch = Mat3A::from_diagonal(Vec3::new(2.0, 0.5, 1.3));
        let a = Mat3A::from_quat(truth) * stretch;
        let mut q = Quat::IDENTITY;
        let frame = extract_rotation(&a, &mut q, 100, LANDING_ANGLE);
        assert!(rotation_angle(q.inverse() * truth) < 1e-4);
        assert_eq!(frame, Mat3A::from_quat(q));
    }

    #[test]
    fn warm_start_converges_in_few_iterations() {
        // Near the answer the Newton step converges quadratically: float precision in two iterations.
        let truth = Quat::from_euler(glam::EulerRot::XYZ, 0.5, 0.2, -0.1);
        let stretch = Mat3A::from_diagonal(Vec3::new(1.0, 0.05, 0.02));
        for a in [Mat3A::from_quat(truth), Mat3A::from_quat(truth) * stretch] {
            let mut q = Quat::from_euler(glam::EulerRot::XYZ, 0.45, 0.22, -0.12);
            let start = rotation_angle(q.inverse() * truth);
            let frame = extract_rotation(&a, &mut q, 1, LANDING_ANGLE);
            assert_eq!(frame, Mat3A::from_quat(q));
            let first = rotation_angle(q.inverse() * truth);
            assert!(first < 0.05 * start, "{first} vs {start}");
            extract_rotation(&a, &mut q, 1, LANDING_ANGLE);
            assert!(rotation_angle(q.inverse() * truth) < 1e-6);
            extract_rotation(&a, &mut q, 12, LANDING_ANGLE);
            assert!(rotation_angle(q.inverse() * truth) < 1e-6);
        }
    }

    /// Rotations `offset` radians from the truth of matrices stretched from isotropic to rod-thin, along a
    /// generic direction and each axis: (matrix, truth, start).
    fn starts_at(offset: f32) -> impl Iterator<Item = (Mat3A, Quat, Quat)> {
        let stretches = [
            Vec3::ONE,
            Vec3::new(2.0, 0.5, 1.3),
            Vec3::new(1.0, 0.3, 0.3),
            Vec3::new(1.0, 0.05, 0.02),
            Vec3::new(1e-2, 1.0, 1e-2),
        ];
        stretches.into_iter().enumerate().flat_map(move |(k, stretch)| {
            [Vec3::new(0.6, -0.48, 0.64), Vec3::X, Vec3::Y, Vec3::Z].into_iter().map(move |direction| {
                let truth = Quat::from_euler(glam::EulerRot::YXZ, 0.8 + k as f32, -0.4, 1.9);
                let a = Mat3A::from_quat(truth) * Mat3A::from_diagonal(stretch);
                (a, truth, truth * Quat::from_scaled_axis(direction * offset))
            })
        })
    }

    /// The largest error left by `extract_rotation` with at most `iterations` from every start `offset` away.
    fn worst_error(offset: f32, iterations: u32) -> f32 {
        worst_error_of_passes(offset, &[(iterations, LANDING_ANGLE)])
    }

    /// The largest error left by `extract_rotation` called once per `(iterations, landing)` of `passes`, each
    /// from where the one before ended, from every start `offset` away.
    fn worst_error_of_passes(offset: f32, passes: &[(u32, f32)]) -> f32 {
        starts_at(offset)
            .map(|(a, truth, mut q)| {
                for &(iterations, landing) in passes {
                    extract_rotation(&a, &mut q, iterations, landing);
                }
                rotation_angle(q.inverse() * truth)
            })
            .fold(0.0, f32::max)
    }

    #[test]
    fn a_landed_newton_step_leaves_no_error_float32_resolves() {
        // The solve stops after a Newton step shorter than LANDING_ANGLE without testing the gradient again.
        // A few float32 roundings of a unit quaternion:
        for offset in [1e-4, 1e-3, 1e-2, 5e-2, 0.2] {
            let worst = worst_error(offset, 8);
            assert!(worst < 1e-6, "{offset}: {worst}");
        }
    }

    #[test]
    fn a_landed_newton_step_leaves_only_rounding() {
        // The longest step that lands is one from about LANDING_ANGLE away; one step from there is all a
        // landing leaves.
        let worst = worst_error(LANDING_ANGLE, 1);
        assert!(worst < 1e-6, "{worst}");
        // From three times as far, one step leaves more than float32 rounding: such a step must not land.
        let worst = worst_error(3.0 * LANDING_ANGLE, 1);
        assert!(worst > 1e-6, "{worst}");
    }

    #[test]
    fn a_rough_pass_leaves_what_the_polishing_pass_removes() {
        // Only the last shape-matching pass of a substep polishes (`landing_angle`).
        assert_eq!(landing_angle(0, 2), ROUGH_LANDING_ANGLE);
        assert_eq!(landing_angle(1, 2), LANDING_ANGLE);
        assert_eq!(landing_angle(0, 1), LANDING_ANGLE);
        let rough = [(POLAR_ITERATIONS, ROUGH_LANDING_ANGLE)];
        let polished = [(POLAR_ITERATIONS, ROUGH_LANDING_ANGLE), (POLAR_ITERATIONS, LANDING_ANGLE)];
        for offset in [1e-3, 1e-2, 5e-2, ROUGH_LANDING_ANGLE, 0.2] {
            // What a rough landing leaves shrinks with the square of the start's distance (quadratic
            // convergence), down to float rounding; printed with `--nocapture`: 0.24 of the square from 5e-2,
            // and from 1e-3 only float rounding is left.
            let left = worst_error_of_passes(offset, &rough);
            println!("rough pass from {offset}: {left:.2e} left, {:.2} of the square", left / (offset * offset));
            assert!(left <= (0.5 * offset * offset).max(1e-6), "rough pass from {offset}: {left}");
            // The polishing pass that follows ends at float rounding, as a polishing pass alone does.
            let both = worst_error_of_passes(offset, &polished);
            assert!(both < 1e-6, "rough then polishing pass from {offset}: {both}");
        }
        // A rough landing does land: from 5e-2 a polishing pass takes a second step, a rough one does not.
        assert!(worst_error_of_passes(5e-2, &rough) > worst_error(5e-2, POLAR_ITERATIONS));
    }

    #[test]
    fn thin_matrix_twist_converges() {
        // A rod-like group: one large singular value. Müller's plain step would crawl on the twist.
        let truth = Quat::from_rotation_y(0.3) * Quat::from_rotation_x(0.2);
        let a = Mat3A::from_quat(truth) * Mat3A::from_diagonal(Vec3::new(1e-2, 1.0, 1e-2));
        let mut q = Quat::from_rotation_x(0.2);
        extract_rotation(&a, &mut q, 8, LANDING_ANGLE);
        assert!(rotation_angle(q.inverse() * truth) < 1e-5, "{}", rotation_angle(q.inverse() * truth));
    }

    #[test]
    fn rank_deficient_matrix_stays_finite() {
        // A two-point group without orientation terms: rank 1.
        let a = Mat3A::from_cols(Vec3A::new(0.0, 1.0, 0.0), Vec3A::ZERO, Vec3A::ZERO);
        let mut q = Quat::IDENTITY;
        extract_rotation(&a, &mut q, 20, LANDING_ANGLE);
        assert!(q.is_finite() && (q.length() - 1.0).abs() < 1e-5);
        // The one constrained column is aligned: x maps to y.
        assert!((q * Vec3::X - Vec3::Y).length() < 1e-3);
    }

    #[test]
    fn zero_matrix_leaves_guess() {
        let mut q = Quat::from_rotation_x(0.3);
        extract_rotation(&Mat3A::ZERO, &mut q, 10, LANDING_ANGLE);
        assert_eq!(q, Quat::from_rotation_x(0.3));
    }
}
