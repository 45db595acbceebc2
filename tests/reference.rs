//! The exact n-pendulum reference used by the accuracy benchmark (`benches/accuracy.rs`, SPEC 6.1) checked
//! against what is known in closed form: energy conservation, the single pendulum's period (small-angle
//! and exact at large amplitude), the double pendulum's normal modes, a uniformly accelerated root, and
//! convergence under a tighter tolerance. Figures print with `--nocapture`.

#[path = "../benches/support/pendulum.rs"]
mod pendulum;

use pendulum::{Pendulum, RootMotion, Tolerance, exact_single_period};
use std::f64::consts::{FRAC_PI_2, PI, SQRT_2};

const G: f64 = 9.81;

/// Chain of `links` equal links, 1 m in total, unit masses, released straight out along +x.
fn horizontal(links: usize) -> (Pendulum, Vec<f64>) {
    let p = Pendulum::uniform(links, 1.0 / links as f64, 1.0, [0.0, -G]);
    let y0 = p.state_at_rest(&vec![FRAC_PI_2; links]);
    (p, y0)
}

/// Times where component `index` of the state crosses zero going down (Newton-refined on the solution).
fn downward_crossings(p: &Pendulum, y0: &[f64], index: usize, end: f64, grid: f64) -> Vec<f64> {
    let steps = (end / grid).round() as usize;
    let times: Vec<f64> = (1..=steps).map(|i| i as f64 * grid).collect();
    let (states, _) = p.solve(0.0, y0, &times, Tolerance::REFERENCE);
    let n = p.links();
    let mut crossings = Vec::new();
    let mut previous = (0.0, y0.to_vec());
    for (t, y) in times.iter().zip(states) {
        if previous.1[index] > 0.0 && y[index] <= 0.0 {
            let (ta, ya) = &previous;
            // Newton on theta(t) = 0 with theta' from the state, each iterate integrated from the grid point.
            let mut tc = ta - ya[index] / ya[index + n];
            for _ in 0..6 {
                let yc = p.advance(*ta, ya, tc, Tolerance::REFERENCE);
                tc -= yc[index] / yc[index + n];
            }
            crossings.push(tc);
        }
        previous = (*t, y);
    }
    crossings
}

fn mean_period(crossings: &[f64]) -> f64 {
    (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
}

#[test]
fn energy_is_conserved_released_horizontally() {
    for links in [2usize, 8] {
        let (p, y0) = horizontal(links);
        let times: Vec<f64> = (1..=200).map(|i| i as f64 * 0.01).collect();
        let (states, work) = p.solve(0.0, &y0, &times, Tolerance::REFERENCE);
        let e0 = p.energy(0.0, &y0);
        // Energy scale: the potential energy released between horizontal and hanging straight down.
        let scale: f64 = (1..=links).map(|i| G * i as f64 / links as f64).sum();
        let worst = times.iter().zip(&states).map(|(t, y)| (p.energy(*t, y) - e0).abs()).fold(0.0, f64::max) / scale;
        let tip_speed =
            states.iter().map(|y| y[links..].iter().map(|w| w.abs()).fold(0.0, f64::max)).fold(0.0, f64::max);
        println!(
            "{links}-link pendulum, 2 s from horizontal: max |dE| / E_scale = {worst:.2e} ({} steps, {} rejected, max link rate {tip_speed:.1} rad/s)",
            work.accepted, work.rejected
        );
        assert!(worst <= 1e-9, "{links} links: relative energy drift {worst}");
    }
}

#[test]
fn single_pendulum_period() {
    let length = 0.5;
    let p = Pendulum::uniform(1, length, 1.0, [0.0, -G]);
    let small = 2.0 * PI * (length / G).sqrt();
    for (theta0, against_small_angle) in [(1e-3, true), (2.5, false)] {
        let exact = exact_single_period(length, G, theta0);
        let y0 = p.state_at_rest(&[theta0]);
        let crossings = downward_crossings(&p, &y0, 0, 5.0 * exact, 1e-2);
        assert!(crossings.len() >= 4);
        let measured = mean_period(&crossings);
        println!(
            "single pendulum, amplitude {theta0} rad: period {measured:.12} s, exact {exact:.12} s (error {:.1e}), small-angle 2 pi sqrt(L/g) {small:.12} s (error {:.1e})",
            measured / exact - 1.0,
            measured / small - 1.0
        );
        assert!((measured / exact - 1.0).abs() < 1e-10, "amplitude {theta0}: {measured} vs exact {exact}");
        if against_small_angle {
            assert!((measured / small - 1.0).abs() < 1e-6, "{measured} vs 2 pi sqrt(L/g) = {small}");
        }
    }
}

#[test]
fn double_pendulum_normal_modes() {
    let l = 0.5;
    let p = Pendulum::uniform(2, l, 1.0, [0.0, -G]);
    let amplitude = 1e-4;
    // omega^2 = (g/l)(2 -+ sqrt 2), with theta_2 / theta_1 = +-sqrt 2.
    for (sign, name) in [(1.0, "slow"), (-1.0, "fast")] {
        let omega = ((G / l) * (2.0 - sign * SQRT_2)).sqrt();
        let theory = 2.0 * PI / omega;
        let y0 = p.state_at_rest(&[amplitude, sign * SQRT_2 * amplitude]);
        let crossings = downward_crossings(&p, &y0, 0, 6.0 * theory, theory / 50.0);
        assert!(crossings.len() >= 5);
        let measured = mean_period(&crossings);
        // In an eigenmode both links cross zero together.
        let ratio_kept = {
            let y = p.advance(0.0, &y0, 2.0 * theory, Tolerance::REFERENCE);
            (y[1] / y[0] - sign * SQRT_2).abs()
        };
        println!(
            "double pendulum {name} mode: period {measured:.10} s, theory {theory:.10} s, relative error {:.1e}; mode shape kept to {ratio_kept:.1e}",
            measured / theory - 1.0
        );
        assert!((measured / theory - 1.0).abs() < 1e-5, "{name} mode: {measured} vs {theory}");
        assert!(ratio_kept < 1e-4, "{name} mode shape drifted by {ratio_kept}");
    }
}

/// A root accelerating uniformly along x: the chain hangs still along gravity minus that acceleration.
#[test]
fn accelerated_root_is_extra_gravity() {
    let a = 3.0;
    let root = move |t: f64| RootMotion {
        position: [0.5 * a * t * t + 2.0 * t, 0.0],
        velocity: [a * t + 2.0, 0.0],
        acceleration: [a, 0.0],
    };
    let p = Pendulum::new(vec![0.25; 4], vec![1.0; 4], [0.0, -G], Box::new(root));
    let theta = -(a / G).atan();
    let y0 = p.state_at_rest(&[theta; 4]);
    let y = p.advance(0.0, &y0, 2.0, Tolerance::REFERENCE);
    let drift = y.iter().zip(&y0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    println!("accelerated root: equilibrium angle {theta:.6} rad held to {drift:.1e} over 2 s");
    assert!(drift < 1e-10, "drift {drift}");
    let positions = p.positions(2.0, &y);
    assert!((positions[0][0] - (2.0 * a + 4.0)).abs() < 1e-12, "root trajectory is applied to positions");
}

/// The reference tolerance is converged: ten times tighter moves no joint of the 8-link pendulum by more
/// than 1e-10 m over the scenarios' 0.5 s.
#[test]
fn reference_tolerance_is_converged() {
    for links in [2usize, 8] {
        let (p, y0) = horizontal(links);
        let times: Vec<f64> = (1..=120).map(|i| i as f64 / 240.0).collect();
        let (a, _) = p.solve(0.0, &y0, &times, Tolerance::REFERENCE);
        let tight = Tolerance {
            relative: Tolerance::REFERENCE.relative / 10.0,
            absolute: Tolerance::REFERENCE.absolute / 10.0,
        };
        let (b, _) = p.solve(0.0, &y0, &times, tight);
        let mut worst = 0.0f64;
        for ((t, ya), yb) in times.iter().zip(&a).zip(&b) {
            for (pa, pb) in p.positions(*t, ya).iter().zip(p.positions(*t, yb)) {
                worst = worst.max(((pa[0] - pb[0]).powi(2) + (pa[1] - pb[1]).powi(2)).sqrt());
            }
        }
        println!("{links}-link: reference vs 10x tighter tolerance, max joint difference {worst:.1e} m over 0.5 s");
        assert!(worst < 1e-10, "{links} links: {worst}");
    }
}
