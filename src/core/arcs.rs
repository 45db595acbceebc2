//! The shortest arcs between many pairs of vectors at once: `math::shortest_arc` of their directions, for
//! every segment of a chain in one loop that the compiler vectorises. One arc is three double-precision square
//! roots and five divisions in a row; called segment by segment (as the momentum suppression did), the
//! arcs of a chain ran one after the other, each waiting on its own divisions (`rod::carry_to_new_rest` was 9 %
//! of the 1000 x 16 *views* frame: `perf record -F 5000` of `scene_cost 100 1000x16 views` at a703489). Written over
//! columns of numbers with no branch in the loop body, four segments share each double-precision instruction
//! (two in the baseline SSE2 copy).
//!
//! The arithmetic is `math::direction`'s and glam's `DQuat::from_rotation_arc`'s, operation for operation
//! (the same glam calls, their branches turned into selects), so every arc has the bits the per-segment calls
//! gave.

use glam::{DQuat, Quat, Vec3};
use multiversion::multiversion;

use super::math::{direction, shortest_arc};

/// Columns of vectors in and arcs out, one entry per pair.
#[derive(Default)]
pub struct ArcColumns {
    from: [Vec<f32>; 3],
    to: [Vec<f32>; 3],
    arcs: [Vec<f32>; 4],
    /// Pairs whose directions are opposite: their arc's axis is glam's choice, computed apart (rare).
    opposite: Vec<bool>,
}

impl ArcColumns {
    /// Room for `n` pairs (allocates only when it grows).
    pub fn reserve(&mut self, n: usize) {
        for column in self.from.iter_mut().chain(&mut self.to).chain(&mut self.arcs) {
            if column.len() < n {
                column.resize(n, 0.0);
            }
        }
        if self.opposite.len() < n {
            self.opposite.resize(n, false);
        }
    }

    /// Sets the first `n` pairs, pair `k` to `pair(k)`. One loop over columns cut to `n`, so that the compiler
    /// drops the bounds checks (set one at a time, each pair's six stores were checked).
    #[inline]
    pub fn set_all(&mut self, n: usize, mut pair: impl FnMut(usize) -> (Vec3, Vec3)) {
        let [fx, fy, fz] = &mut self.from;
        let [tx, ty, tz] = &mut self.to;
        let (fx, fy, fz, tx, ty, tz) =
            (&mut fx[..n], &mut fy[..n], &mut fz[..n], &mut tx[..n], &mut ty[..n], &mut tz[..n]);
        for k in 0..n {
            let (from, to) = pair(k);
            (fx[k], fy[k], fz[k]) = (from.x, from.y, from.z);
            (tx[k], ty[k], tz[k]) = (to.x, to.y, to.z);
        }
    }

    /// The arcs of the first `n` pairs: [`arcs`](Self::arcs) reads them.
    pub fn compute(&mut self, n: usize) {
        let [fx, fy, fz] = &self.from;
        let [tx, ty, tz] = &self.to;
        let [ax, ay, az, aw] = &mut self.arcs;
        arcs(
            [&fx[..n], &fy[..n], &fz[..n]],
            [&tx[..n], &ty[..n], &tz[..n]],
            [&mut ax[..n], &mut ay[..n], &mut az[..n], &mut aw[..n]],
            &mut self.opposite[..n],
        );
    }

    /// The arcs of the first `n` pairs, in order: pair `k`'s is `shortest_arc(direction(from), direction(to))`,
    /// the identity where either vector has no direction (`math::direction`'s `None`).
    #[inline]
    pub fn arcs(&self, n: usize) -> impl Iterator<Item = Quat> + '_ {
        let [x, y, z, w] = &self.arcs;
        let columns = x[..n].iter().zip(&y[..n]).zip(&z[..n]).zip(&w[..n]).zip(&self.opposite[..n]);
        columns.enumerate().map(
            |(k, ((((&x, &y), &z), &w), &opposite))| {
                if opposite { self.exact(k) } else { Quat::from_xyzw(x, y, z, w) }
            },
        )
    }

    #[cold]
    #[inline(never)]
    fn exact(&self, k: usize) -> Quat {
        let column = |c: &[Vec<f32>; 3]| Vec3::new(c[0][k], c[1][k], c[2][k]);
        match (direction(column(&self.from)), direction(column(&self.to))) {
            (Some(from), Some(to)) => shortest_arc(from, to),
            _ => Quat::IDENTITY,
        }
    }
}

/// Branch-free over the pairs (the per-pair choices are selects), so that the loop vectorises: an AVX2 copy
/// where the CPU has it (four doubles per instruction), the baseline's otherwise; the same bits either way
/// (no fused operations).
#[multiversion(targets("x86_64+avx2"))]
fn arcs(from: [&[f32]; 3], to: [&[f32]; 3], out: [&mut [f32]; 4], opposite: &mut [bool]) {
    const ONE_MINUS_EPS: f64 = 1.0 - 2.0 * f64::EPSILON;
    let min_length = f32::MIN_POSITIVE.sqrt();
    // Every column cut to one length: no bounds checks in the loop.
    let n = opposite.len();
    let [fx, fy, fz] = from.map(|c| &c[..n]);
    let [tx, ty, tz] = to.map(|c| &c[..n]);
    let [ax, ay, az, aw] = out.map(|c| &mut c[..n]);
    for k in 0..n {
        // `math::direction` of each, without its branch.
        let (f, t) = (Vec3::new(fx[k], fy[k], fz[k]), Vec3::new(tx[k], ty[k], tz[k]));
        let (f_length, t_length) = (f.length(), t.length());
        let found = (f_length > min_length) & f_length.is_finite() & (t_length > min_length) & t_length.is_finite();
        let (f, t) = ((f / f_length).as_dvec3().normalize(), (t / t_length).as_dvec3().normalize());
        // `DQuat::from_rotation_arc`: the identity within its tolerance of parallel, glam's own axis within it
        // of opposite (`ArcColumns::exact`).
        let dot = f.dot(t);
        let c = f.cross(t);
        let arc = DQuat::from_xyzw(c.x, c.y, c.z, 1.0 + dot).normalize();
        let identity = !found | (dot > ONE_MINUS_EPS);
        opposite[k] = found & (dot < -ONE_MINUS_EPS);
        // `as_quat`, component by component: glam's `Quat` is an SSE register, which keeps the loop scalar.
        let pick = |part: f64, unit: f32| if identity { unit } else { part as f32 };
        (ax[k], ay[k], az[k], aw[k]) = (pick(arc.x, 0.0), pick(arc.y, 0.0), pick(arc.z, 0.0), pick(arc.w, 1.0));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_arc_has_the_bits_of_the_per_pair_call() {
        let mut pairs = vec![
            (Vec3::X, Vec3::Y),
            (Vec3::new(0.3, -1.2, 0.7), Vec3::new(0.31, -1.19, 0.71)),
            (Vec3::new(1e-3, 2e-3, -4e-3), Vec3::new(-2.0, 0.5, 0.25)),
            // Parallel, opposite, and vectors with no direction.
            (Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.0, 0.5, 0.0)),
            (Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, -3.0)),
            (Vec3::new(1.0, 2.0, 3.0), Vec3::new(-2.0, -4.0, -6.0)),
            (Vec3::ZERO, Vec3::Y),
            (Vec3::X, Vec3::splat(1e-30)),
            (Vec3::new(f32::INFINITY, 0.0, 0.0), Vec3::Y),
            (Vec3::Y, Vec3::new(f32::NAN, 1.0, 0.0)),
        ];
        // And a spread of ordinary ones, more than a vector's width so the loop's body and tail both run.
        for k in 0..37 {
            let a = k as f32 * 0.37;
            pairs.push((
                Vec3::new(a.cos(), (1.3 * a).sin(), 0.2 * a - 1.0),
                Vec3::new((0.7 * a).sin(), a.cos() + 0.1, 0.5 - 0.03 * a),
            ));
        }
        let mut columns = ArcColumns::default();
        columns.reserve(pairs.len());
        columns.set_all(pairs.len(), |k| pairs[k]);
        columns.compute(pairs.len());
        for (k, (&(from, to), got)) in pairs.iter().zip(columns.arcs(pairs.len())).enumerate() {
            let expected = match (direction(from), direction(to)) {
                (Some(from), Some(to)) => shortest_arc(from, to),
                _ => Quat::IDENTITY,
            };
            assert_eq!(
                got.to_array().map(f32::to_bits),
                expected.to_array().map(f32::to_bits),
                "pair {k}: {from} to {to}"
            );
        }
        assert!(columns.opposite[4] && columns.opposite[5], "opposite pairs take glam's axis");
    }
}
