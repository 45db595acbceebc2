//! The body of shape matching's sweep (`kernel::match_shape`) for one group, as loops over the lanes whose
//! bodies are one lane's scalar code, each loop in one precision: the centre and the members' spans (double),
//! the group matrix (single), the polar decomposition ([`polar::extract_rotation`]), the turned rest offsets
//! and the middle member's orientation (single), the pulls (double). Written with the lane types' operations,
//! the sweep ran a fifth of its instructions 128-bit wide and a quarter on the stack; with a loop mixing the
//! two precisions the compiler vectorised it 4 lanes at a time, its single-precision half in 128-bit
//! registers (48 % of the sweep's instructions, `tools/instruction_mix.py`). The arithmetic is the lane
//! types' operations in their order: the same bits.
//!
//! The sweep that runs the groups (`kernel::sweep`) is a function of its own taking every buffer as a separate
//! slice, for the compiler to vectorise these loops (see there).

use super::polar;
use super::scalar::{Mat, Quaternion, Vec, dot4, from_quat, mul};
use super::simd::{D, DV3, F, M3, Q, V3};
use crate::core::rod::THIRD;

type DVec = [f64; 3];

/// A group's constants: the orientation terms' weight and the pull per iteration (single and double precision).
#[derive(Clone, Copy)]
pub struct Stiffness<const L: usize> {
    pub orientation_weight: F<L>,
    pub alpha: F<L>,
    pub alpha64: D<L>,
}

/// One group of the sweep: its members `lower`, `middle` and (`FULL`) `upper` pulled towards the rest offsets
/// `offsets` turned by the group's rotation, which `rotation` holds from the last pass and takes from the
/// polar decomposition of the group matrix (landing below `landing`); the middle member's predicted rotation
/// `qp` turned towards it times its rest rotation `qbar`. `lower_turn` is the lower member's predicted rotation
/// and inverse rest rotation (the group before changed it), `terms` the middle and upper members' orientation
/// terms, taken before the sweep.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn match_group<const L: usize, const FULL: bool>(
    lower: &mut DV3<L>,
    middle: &mut DV3<L>,
    upper: &mut DV3<L>,
    offsets: &[V3<L>; 3],
    lower_turn: [&Q<L>; 2],
    terms: [&M3<L>; 2],
    rotation: &mut Q<L>,
    qbar: &Q<L>,
    qp: &mut Q<L>,
    stiffness: &Stiffness<L>,
    landing: f32,
) {
    // Each lane loop holds one precision (see the module's documentation).
    let mut c = DV3::ZERO;
    let mut to_members = [V3::ZERO; 2];
    centre_and_spans::<L, FULL>(lower, middle, upper, &mut c, &mut to_members);
    let mut a = M3::ZERO;
    group_matrix::<L, FULL>(&to_members, offsets, lower_turn, terms, &stiffness.orientation_weight, &mut a);
    let frame = polar::extract_rotation(&a, rotation, landing);
    let mut goals = [V3::ZERO; 3];
    turn_offsets::<L, FULL>(offsets, &frame, rotation, qbar, qp, &stiffness.alpha, &mut goals);
    pull_members::<L, FULL>(lower, middle, upper, &c, &goals, &stiffness.alpha64);
}

/// The centre `c` of the members, and the lower and (`FULL`) upper members' offsets from the middle one.
#[inline(always)]
fn centre_and_spans<const L: usize, const FULL: bool>(
    lower: &DV3<L>,
    middle: &DV3<L>,
    upper: &DV3<L>,
    c: &mut DV3<L>,
    [to_lower, to_upper]: &mut [V3<L>; 2],
) {
    for lane in 0..L {
        let (lower, middle, upper) = (lower.get(lane), middle.get(lane), upper.get(lane));
        to_lower.set(lane, to_f32(sub(lower, middle)));
        if FULL {
            to_upper.set(lane, to_f32(sub(upper, middle)));
            let centre = |k: usize| (0.0 + lower[k] + middle[k] + upper[k]) * THIRD;
            c.set(lane, [centre(0), centre(1), centre(2)]);
        } else {
            let centre = |k: usize| (0.0 + lower[k] + middle[k]) / 2.0;
            c.set(lane, [centre(0), centre(1), centre(2)]);
        }
    }
}

/// The group matrix `a`: the members' orientation terms and the outer products of their offsets from the middle
/// member with their rest offsets.
#[inline(always)]
fn group_matrix<const L: usize, const FULL: bool>(
    [to_lower, to_upper]: &[V3<L>; 2],
    offsets: &[V3<L>; 3],
    [lower_qp, lower_qbar_inv]: [&Q<L>; 2],
    [middle_term, upper_term]: [&M3<L>; 2],
    weight: &F<L>,
    a: &mut M3<L>,
) {
    for lane in 0..L {
        let turn = mul(lower_qp.get(lane), lower_qbar_inv.get(lane));
        let lower_term = scale_matrix(from_quat(turn), weight.0[lane]);
        let (middle_term, upper_term) = (middle_term.get(lane), upper_term.get(lane));
        let (to_lower, r_lower) = (to_lower.get(lane), offsets[0].get(lane));
        let mut matrix = [[0.0; 3]; 3];
        for column in 0..3 {
            for row in 0..3 {
                matrix[column][row] =
                    lower_term[column][row] + to_lower[row] * r_lower[column] + middle_term[column][row];
            }
        }
        if FULL {
            let (to_upper, r_upper) = (to_upper.get(lane), offsets[2].get(lane));
            for column in 0..3 {
                for row in 0..3 {
                    matrix[column][row] =
                        matrix[column][row] + upper_term[column][row] + to_upper[row] * r_upper[column];
                }
            }
        }
        a.set(lane, matrix);
    }
}

/// The members' rest offsets turned by the group's `frame` (`goals`, relative to the centre); the middle
/// member's predicted rotation `qp` turned by `alpha` towards the group's `rotation` times its rest rotation
/// `qbar`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn turn_offsets<const L: usize, const FULL: bool>(
    offsets: &[V3<L>; 3],
    frame: &M3<L>,
    rotation: &Q<L>,
    qbar: &Q<L>,
    qp: &mut Q<L>,
    alpha: &F<L>,
    goals: &mut [V3<L>; 3],
) {
    for lane in 0..L {
        let frame = frame.get(lane);
        for member in 0..if FULL { 3 } else { 2 } {
            goals[member].set(lane, mul_vec3(&frame, offsets[member].get(lane)));
        }
        let target = mul(rotation.get(lane), qbar.get(lane));
        qp.set(lane, nlerp_shorter(qp.get(lane), target, alpha.0[lane]));
    }
}

/// Each member pulled by `alpha` towards its goal, the centre `c` plus its turned offset.
#[inline(always)]
fn pull_members<const L: usize, const FULL: bool>(
    lower: &mut DV3<L>,
    middle: &mut DV3<L>,
    upper: &mut DV3<L>,
    c: &DV3<L>,
    goals: &[V3<L>; 3],
    alpha: &D<L>,
) {
    for lane in 0..L {
        let (centre, pull) = (c.get(lane), alpha.0[lane]);
        lower.set(lane, pull_to_goal(lower.get(lane), centre, goals[0].get(lane), pull));
        middle.set(lane, pull_to_goal(middle.get(lane), centre, goals[1].get(lane), pull));
        if FULL {
            upper.set(lane, pull_to_goal(upper.get(lane), centre, goals[2].get(lane), pull));
        }
    }
}

/// `kernel::pull_to_goal`.
#[inline(always)]
fn pull_to_goal(p: DVec, centre: DVec, offset: Vec, alpha: f64) -> DVec {
    let pull = |k: usize| p[k] + (centre[k] + offset[k] as f64 - p[k]) * alpha;
    [pull(0), pull(1), pull(2)]
}

/// `M3::mul_vec3`.
#[inline(always)]
fn mul_vec3(m: &Mat, v: Vec) -> Vec {
    let row = |r: usize| m[0][r] * v[0] + m[1][r] * v[1] + m[2][r] * v[2];
    [row(0), row(1), row(2)]
}

/// `M3::scale`.
#[inline(always)]
fn scale_matrix(m: Mat, s: f32) -> Mat {
    let column = |c: Vec| [c[0] * s, c[1] * s, c[2] * s];
    [column(m[0]), column(m[1]), column(m[2])]
}

/// `Q::nlerp_shorter`: `from` turned by `t` towards `to` (or `-to`, whichever is nearer), normalised.
#[inline(always)]
fn nlerp_shorter(from: Quaternion, to: Quaternion, t: f32) -> Quaternion {
    let to = if dot4(to, from) < 0.0 { [-to[0], -to[1], -to[2], -to[3]] } else { to };
    let keep = 1.0 - t;
    let mix = |k: usize| from[k] * keep + to[k] * t;
    let mixed = [mix(0), mix(1), mix(2), mix(3)];
    let inv = 1.0 / dot4(mixed, mixed).sqrt();
    [mixed[0] * inv, mixed[1] * inv, mixed[2] * inv, mixed[3] * inv]
}

#[inline(always)]
fn sub(a: DVec, b: DVec) -> DVec {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline(always)]
fn to_f32(v: DVec) -> Vec {
    [v[0] as f32, v[1] as f32, v[2] as f32]
}
