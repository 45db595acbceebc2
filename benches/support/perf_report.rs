//! Collecting the performance benchmark's numbers and writing `docs/performance.md`.
//!
//! Frame times come from criterion's own measurement loop: every `iter_custom` call of a benchmark records
//! its time per frame here, and the median over the calls of its measurement phase (the last
//! `sample_size` calls; the warm-up calls come first) is the same statistic criterion prints as the median.
#![allow(dead_code)]

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::hint::black_box;
use std::time::{Duration, Instant};

use crate::peak::{Divider, Peak};

// ---- allocation counting -----------------------------------------------------------------------------

/// The tests' counting allocator, so the report can show that a frame allocates nothing.
#[path = "../../tests/common/counting.rs"]
mod counting;
pub use counting::Counting;

/// Allocations (including reallocations) per call of `frame`, over `frames` calls.
pub fn allocations_per_frame(frames: u32, mut frame: impl FnMut()) -> f64 {
    let before = counting::allocations();
    for _ in 0..frames {
        frame();
    }
    (counting::allocations() - before) as f64 / frames as f64
}

// ---- timing ---------------------------------------------------------------------------------------------

pub fn median(mut values: Vec<f64>) -> f64 {
    assert!(!values.is_empty(), "median of nothing");
    values.sort_by(f64::total_cmp);
    let n = values.len();
    if n % 2 == 1 { values[n / 2] } else { 0.5 * (values[n / 2 - 1] + values[n / 2]) }
}

/// Time per frame of every `iter_custom` call, per benchmark id.
#[derive(Default)]
pub struct Recorder {
    samples: RefCell<BTreeMap<String, Vec<f64>>>,
}

impl Recorder {
    /// Runs `iters` frames, records the time per frame under `id`, and returns the total for criterion.
    pub fn time(&self, id: &str, iters: u64, mut frame: impl FnMut()) -> Duration {
        let start = Instant::now();
        for _ in 0..iters {
            frame();
        }
        let elapsed = start.elapsed();
        self.samples.borrow_mut().entry(id.to_owned()).or_default().push(elapsed.as_secs_f64() / iters as f64);
        elapsed
    }

    /// Median seconds per frame over the last `sample_size` calls (criterion's measurement phase), `None` if
    /// the benchmark did not run (filtered out).
    pub fn median_frame(&self, id: &str, sample_size: usize) -> Option<f64> {
        let samples = self.samples.borrow();
        let all = samples.get(id)?;
        Some(median(all[all.len().saturating_sub(sample_size)..].to_vec()))
    }
}

/// A ratio measured by interleaving two runs (A B, then B A, ...) so that a load change on the shared
/// machine hits both alike; the median over rounds of (time of B / time of A).
#[derive(Clone, Debug)]
pub struct PairedRatio {
    pub what: String,
    pub a: String,
    pub b: String,
    pub a_seconds: f64,
    pub b_seconds: f64,
    pub ratio: f64,
    pub rounds: usize,
    /// For a ratio pooled over pairs of runs ([`pooled_paired_ratio`]): the smallest and largest of the pairs'
    /// own medians.
    pub pair_range: Option<(f64, f64)>,
    /// The pairs of runs pooled (1 for [`paired_ratio`]).
    pub pairs: usize,
}

/// Interleaves blocks of frames of `a` and `b` for `rounds` rounds; each block lasts about `block`.
pub fn paired_ratio(
    what: &str,
    (a_name, a): (&str, &mut dyn FnMut()),
    (b_name, b): (&str, &mut dyn FnMut()),
    rounds: usize,
    block: Duration,
) -> PairedRatio {
    let times = paired_rounds(a, b, rounds, block);
    times.ratio(what, a_name, b_name)
}

/// [`paired_ratio`] over `pairs` pairs of runs made afresh (A first, then B first, in turn), the rounds
/// shared among them, and the median taken over every round of every pair. Where the allocator puts two
/// runs' hot arrays (their cache sets, their distance modulo 4 KiB) can slow one of them by several percent
/// for its whole life: with one pair that shift is part of the ratio, and differs from run to run.
pub fn pooled_paired_ratio(
    what: &str,
    (a_name, make_a): (&str, &dyn Fn() -> Box<dyn FnMut()>),
    (b_name, make_b): (&str, &dyn Fn() -> Box<dyn FnMut()>),
    pairs: usize,
    rounds: usize,
    block: Duration,
) -> PairedRatio {
    let mut pooled = RoundTimes::default();
    let mut pair_range = (f64::INFINITY, f64::NEG_INFINITY);
    for pair in 0..pairs {
        let (mut a, mut b) = if pair % 2 == 0 {
            let a = make_a();
            (a, make_b())
        } else {
            let b = make_b();
            (make_a(), b)
        };
        let times = paired_rounds(&mut *a, &mut *b, rounds.div_ceil(pairs), block);
        let own = median(times.ratios());
        pair_range = (pair_range.0.min(own), pair_range.1.max(own));
        pooled.a.extend(times.a);
        pooled.b.extend(times.b);
        // Each pair's runs are dropped before the next pair's are made.
        drop((a, b));
    }
    PairedRatio { pair_range: Some(pair_range), pairs, ..pooled.ratio(what, a_name, b_name) }
}

/// Seconds per frame of each round's block of A and of B.
#[derive(Default)]
struct RoundTimes {
    a: Vec<f64>,
    b: Vec<f64>,
}

impl RoundTimes {
    /// B / A, round by round.
    fn ratios(&self) -> Vec<f64> {
        self.a.iter().zip(&self.b).map(|(x, y)| y / x).collect()
    }

    fn ratio(self, what: &str, a_name: &str, b_name: &str) -> PairedRatio {
        let ratios = self.ratios();
        PairedRatio {
            what: what.into(),
            a: a_name.into(),
            b: b_name.into(),
            rounds: ratios.len(),
            a_seconds: median(self.a),
            b_seconds: median(self.b),
            ratio: median(ratios),
            pair_range: None,
            pairs: 1,
        }
    }
}

fn paired_rounds(mut a: &mut dyn FnMut(), mut b: &mut dyn FnMut(), rounds: usize, block: Duration) -> RoundTimes {
    let once = |f: &mut dyn FnMut()| {
        let start = Instant::now();
        f();
        start.elapsed().as_secs_f64()
    };
    // Calibrate the block length on the slower of the two (after one warm frame each).
    once(&mut a);
    once(&mut b);
    let frames = frames_per_block(once(&mut a).max(once(&mut b)), block);
    let run = |f: &mut dyn FnMut()| {
        let start = Instant::now();
        for _ in 0..frames {
            f();
        }
        start.elapsed().as_secs_f64() / frames as f64
    };
    let mut times = RoundTimes::default();
    for round in 0..rounds {
        let (x, y) = if round % 2 == 0 {
            let x = run(&mut a);
            (x, run(&mut b))
        } else {
            let y = run(&mut b);
            (run(&mut a), y)
        };
        times.a.push(x);
        times.b.push(y);
    }
    times
}

/// The lane solver's time per joint and substep against the lower bound measured alongside it: each round
/// measures the arithmetic peaks (best of two passes each) and then times a block of frames (their median), or
/// the other way round, so that both see the same clock. This VM's clock moves within a run: the rounds' bounds range by a
/// fifth and more (the report prints the range), so a peak measured once at the start, against frame medians
/// taken minutes later, moves the ratio by as much.
pub struct BoundRatio {
    /// Median over the rounds of measured / bound.
    pub ratio: f64,
    /// Medians over the rounds, seconds per joint and substep.
    pub measured: f64,
    pub bound: f64,
    /// The smallest and largest bound of a round, seconds per joint and substep.
    pub bound_range: (f64, f64),
    pub rounds: usize,
}

/// [`BoundRatio`] of `frame`, which runs one frame of `dynamic_joints` joints and returns the substeps it took,
/// over `rounds` rounds of blocks of about `block`.
pub fn interleaved_bound_ratio(
    frame: &mut dyn FnMut() -> u32,
    dynamic_joints: f64,
    bandwidth: f64,
    rounds: usize,
    block: Duration,
) -> BoundRatio {
    let sixteen = kodawari::simd_path() == "avx512";
    frame();
    let start = Instant::now();
    let substeps_per_frame = f64::from(frame().max(1));
    let frames = frames_per_block(start.elapsed().as_secs_f64(), block);
    // Seconds per joint and substep over one block of frames: the median frame, as the peaks take their best
    // pass, so that another process's time slice in the block moves neither.
    let mut time_frames = || {
        let per_frame = (0..frames)
            .map(|_| {
                let start = Instant::now();
                let substeps = frame().max(1);
                start.elapsed().as_secs_f64() / (f64::from(substeps) * dynamic_joints)
            })
            .collect();
        median(per_frame)
    };
    let bound = || Bound::at(Peak::measure_with(sixteen, 2), bandwidth, substeps_per_frame).lanes();
    let (mut measured, mut bounds) = (Vec::new(), Vec::new());
    for round in 0..rounds {
        let (m, b) = if round % 2 == 0 {
            let b = bound();
            (time_frames(), b)
        } else {
            let m = time_frames();
            (m, bound())
        };
        measured.push(m);
        bounds.push(b);
    }
    let ratios = measured.iter().zip(&bounds).map(|(m, b)| m / b).collect();
    let bound_range = bounds.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &b| (lo.min(b), hi.max(b)));
    BoundRatio { ratio: median(ratios), measured: median(measured), bound: median(bounds), bound_range, rounds }
}

/// Frames of `frame_seconds` each that fill a block of about `block`.
fn frames_per_block(frame_seconds: f64, block: Duration) -> u64 {
    ((block.as_secs_f64() / frame_seconds.max(1e-9)).ceil() as u64).max(1)
}

// ---- the machine ----------------------------------------------------------------------------------------

pub struct Machine {
    pub cpu_model: String,
    /// Logical CPUs (`/proc/cpuinfo` processors) and what the process may use.
    pub processors: usize,
    pub available_parallelism: usize,
    pub mhz: Option<f64>,
    pub simd_flags: Vec<String>,
    pub l3_cache: Option<String>,
    pub load_average: Option<String>,
    pub rustc: Option<String>,
    /// Single-thread streaming bandwidth (bytes/s), measured here.
    pub bandwidth: f64,
    /// Single-thread arithmetic peaks, measured here.
    pub peak: Peak,
}

impl Machine {
    pub fn probe() -> Self {
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let field = |name: &str| {
            cpuinfo
                .lines()
                .find(|l| l.split(':').next().is_some_and(|k| k.trim() == name))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_owned())
        };
        let flags = field("flags").unwrap_or_default();
        let simd_flags = ["sse4_2", "avx", "avx2", "fma", "avx512f", "neon", "asimd"]
            .iter()
            .filter(|f| flags.split_whitespace().any(|x| x == **f))
            .map(|f| f.to_string())
            .collect();
        let read = |path: &str| std::fs::read_to_string(path).ok().map(|s| s.trim().to_owned());
        let rustc = std::process::Command::new("rustc")
            .arg("-V")
            .output()
            .ok()
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned());
        Self {
            // The family and model tell CPU generations apart that share a name (AMD's first- and
            // third-generation Zen are both "AMD EPYC" in a virtual machine; stops 41 and 42 measured one each).
            cpu_model: match (field("model name"), field("cpu family"), field("model")) {
                (Some(name), Some(family), Some(model)) => format!("{name}, family {family}, model {model}"),
                (name, _, _) => name.unwrap_or_else(|| "unknown".into()),
            },
            processors: cpuinfo.lines().filter(|l| l.starts_with("processor")).count(),
            available_parallelism: std::thread::available_parallelism().map_or(1, |n| n.get()),
            mhz: field("cpu MHz").and_then(|v| v.parse().ok()),
            simd_flags,
            l3_cache: read("/sys/devices/system/cpu/cpu0/cache/index3/size"),
            load_average: read("/proc/loadavg"),
            rustc,
            bandwidth: stream_bandwidth(),
            peak: Peak::measure(kodawari::simd_path() == "avx512"),
        }
    }
}

/// Single-thread memory bandwidth: the best of a few passes of `b[i] = s * a[i]` over two 64 MiB arrays
/// (twice the last-level cache of most machines), counting 16 bytes per element as STREAM does.
fn stream_bandwidth() -> f64 {
    const ELEMENTS: usize = 8 << 20;
    let a = vec![1.0f64; ELEMENTS];
    let mut b = vec![0.0f64; ELEMENTS];
    let mut best = f64::INFINITY;
    for pass in 0..6 {
        let s = black_box(1.0 + pass as f64);
        let start = Instant::now();
        for (y, x) in b.iter_mut().zip(&a) {
            *y = s * x;
        }
        black_box(&mut b);
        best = best.min(start.elapsed().as_secs_f64());
    }
    (16 * ELEMENTS) as f64 / best
}

// ---- a lower bound for the rod --------------------------------------------------------------------------

/// One part of a substep's work per dynamic joint ([`SUBSTEP_WORK`]): its single- and double-precision
/// operations, and the divisions and square roots among them.
pub struct Work {
    pub part: &'static str,
    pub f32_operations: f64,
    pub f64_operations: f64,
    pub f32_divisions: f64,
    pub f32_roots: f64,
    pub f64_divisions: f64,
    pub f64_roots: f64,
}

/// Work of one internal substep per dynamic joint at default settings, counted from the lane kernel's code
/// (`src/core/lanes/`: the scalar solver's operations, lane by lane). Counting rule: add, subtract, multiply,
/// divide and square root 1 operation each; loop control, comparisons, selects and conversions free. Building
/// blocks: quaternion product 28, quaternion to matrix 24, normalise 13 (a square root and a division among
/// them), the exponential's series 26, the logarithm's series 21 (a division). Where the code iterates to a
/// tolerance the minimum it runs is counted (one polar step per group, one forward pass and one back
/// substitution per inextensibility solve), so the total is a lower bound for the algorithm as written.
///
/// The divisions and square roots run on a divider that takes a new operation only every few cycles, so the
/// bound prices them at their own measured rates (`Peak`'s dividers), not at the multiplies' and adds'.
/// `tools/arithmetic_ops.py` counts what runs, from callgrind: on `scene_cost 20 1000x16` (built at 1b3bce5) 1 513
/// single- and 417 double-precision operations per joint per substep, among them 14.37 single-precision
/// divisions, 7.47 square roots and 10.74 double-precision divisions, above the minimums counted here: second
/// polar passes, and forward passes of the inextensibility solve beyond one: 2.64 per solve on average at
/// 4bb5b3d, 1.43 since the warm start (`src/core/warm_start.rs`; the calls of `first_pass8` and
/// `corrected_pass8` in the callgrind of `scene_cost 20 1000x16 lanes`).
pub const SUBSTEP_WORK: [Work; 5] = [
    // Velocity relative to the root, decay and gravity (15), angular decay (3), position predict (3 f32, 3
    // f64), orientation predict: scaled turn (3), exponential (26), product (28), normalise (13).
    Work::new("predict", (91.0, 3.0), [1.0, 1.0, 0.0, 0.0]),
    // Per iteration (2 at default) of an interior group: 2 orientation terms (product 28, to matrix 24, weight
    // 9) = 122; centroid (9 adds, 3 multiplications by a third: f64); the outer and lower members' offsets from
    // the middle one (6 f64), their outer products (18) and the sum of 5 matrices (36); the polar step: its
    // guard (20, the matrix's norm: a square root), one step (rotation matrix 24, S = R^T A 45, gradient and
    // trace 5, Mueller's step 5 (a division), convergence 5, the Newton step 58 (a division), the Cayley turn
    // 3, product 28, renormalise 13 = 186), the final matrix (24); goals for 3 particles (matrix times offset
    // 15 each; in f64 the goal and the pull, 12 each); orientation: product (28) and nlerp (33: a normalise).
    // Per iteration 512 f32 and 54 f64, times 2; per iteration 4 single-precision divisions (Mueller's,
    // Newton's, the two normalisations') and 3 square roots (the guard's, the normalisations'). Until stop 31
    // this counted the exponential's series (26) that stop 30's Cayley turn replaced, the offset and outer
    // product of the middle member, and 3 divisions and 2 square roots per iteration; until stop 41 the
    // centroid divided by 3 (3 double-precision divisions per iteration).
    Work::new("shape matching, 2 iterations", (1024.0, 108.0), [8.0, 6.0, 0.0, 0.0]),
    // Start bonds (3, once per substep); per iteration and bond, all f64: the forward pass row (bond 3,
    // residual 7, three dot products 15, elimination 9 with its pivot's division = 34), back substitution (2),
    // the error after the step (18), applying the multipliers (12) = 66, times 2.
    Work::new("inextensibility, 2 iterations", (0.0, 135.0), [0.0, 0.0, 2.0, 0.0]),
    // Linear velocity (3 f64, 3 f32); relative rotation (28), hemisphere (7), logarithm's series (21), scale
    // (3).
    Work::new("velocities", (62.0, 3.0), [1.0, 0.0, 0.0, 0.0]),
    // Per frame, shared by the 4 substeps of a 60 Hz frame: local capture (2 x ~40), interpolated output
    // (~60), world read-back (~35) = 175 / 4. Divisions and square roots per frame: the two captures'
    // normalise (2 + 2), the output's nlerp (1 + 1), three bone directions (9 divisions, 3 square roots), the
    // swing's normalise (1 + 1) = 13 and 7, / 4.
    Work::new("output and read-back, per substep share", (44.0, 0.0), [3.25, 1.75, 0.0, 0.0]),
];

impl Work {
    /// `part`'s (single, double)-precision operations, and among them `[f32 divisions, f32 square roots, f64
    /// divisions, f64 square roots]`.
    const fn new(part: &'static str, (f32_operations, f64_operations): (f64, f64), divider: [f64; 4]) -> Self {
        let [f32_divisions, f32_roots, f64_divisions, f64_roots] = divider;
        Self { part, f32_operations, f64_operations, f32_divisions, f32_roots, f64_divisions, f64_roots }
    }
}

/// Bytes a frame streams per joint when the scene does not fit in cache (the chain loop runs all substeps
/// of a chain back to back, so within a frame a chain's data stays in L1 after its first substep).
pub const FRAME_BYTES: [(&str, f64); 5] = [
    // RodState: x DVec3 24 + v Vec3 12 + q Quat 16 + w Vec3 12 + group_rotation Quat 16 = 80, read and written.
    ("particle state (80 B, read + write)", 160.0),
    // rest and rest_used (Vec3 + Quat = 28 B each), segment length (4 B).
    ("rest shapes and lengths (read)", 60.0),
    // local_previous / local_current: one Transform (28 B) written each of the last two substeps.
    ("render states (write)", 56.0),
    // Output: both render states read (56), output written (28), bone axis read (12).
    ("interpolated output", 96.0),
    // read_world: output read (28), host buffer written (28).
    ("host read-back", 56.0),
];

/// Bytes of engine data per joint that a frame touches (state 80, rest shapes 56, length 4, render states
/// 56, output 28, bone axis 12): what must fit in cache for a scene to run out of cache.
pub const WORKING_SET_BYTES_PER_JOINT: f64 = 236.0;

pub struct Bound {
    /// The sum of `SUBSTEP_WORK`.
    pub work: Work,
    pub bytes_per_joint_frame: f64,
    /// Seconds per joint per substep if the operations ran at the measured scalar peak.
    pub scalar_compute: f64,
    /// Same at the measured SIMD peaks of the widest kernel that ran, each precision at its own rate.
    pub simd_compute: f64,
    pub peak: Peak,
    /// Seconds per joint per substep to stream the frame's bytes at the measured bandwidth.
    pub memory: f64,
}

impl Bound {
    pub fn new(machine: &Machine, substeps_per_frame: f64) -> Self {
        Self::at(machine.peak, machine.bandwidth, substeps_per_frame)
    }

    /// The bound at the arithmetic peaks `peak` and the stream bandwidth `bandwidth` (bytes/s).
    pub fn at(peak: Peak, bandwidth: f64, substeps_per_frame: f64) -> Self {
        for w in &SUBSTEP_WORK {
            let fits =
                w.f32_divisions + w.f32_roots <= w.f32_operations && w.f64_divisions + w.f64_roots <= w.f64_operations;
            assert!(fits, "{}: more divisions and square roots than operations", w.part);
        }
        let total = |pick: fn(&Work) -> f64| SUBSTEP_WORK.iter().map(pick).sum::<f64>();
        let work = Work::new(
            "total",
            (total(|w| w.f32_operations), total(|w| w.f64_operations)),
            [total(|w| w.f32_divisions), total(|w| w.f32_roots), total(|w| w.f64_divisions), total(|w| w.f64_roots)],
        );
        let bytes: f64 = FRAME_BYTES.iter().map(|(_, n)| n).sum();
        let w = &work;
        // Multiplies and adds at their rate, divisions and square roots at theirs.
        let time = |operations: f64, divisions: f64, roots: f64, arithmetic: f64, divider: Divider| {
            (operations - divisions - roots) / arithmetic + divisions / divider.division + roots / divider.root
        };
        let f32_time = |arithmetic, divider| time(w.f32_operations, w.f32_divisions, w.f32_roots, arithmetic, divider);
        let f64_time = |arithmetic, divider| time(w.f64_operations, w.f64_divisions, w.f64_roots, arithmetic, divider);
        Self {
            // The scalar solver's double-precision multiplies and adds run at its floats' rate: one lane either
            // way (not so its divisions and square roots).
            scalar_compute: f32_time(peak.scalar_f32, peak.scalar_f32_divider)
                + f64_time(peak.scalar_f32, peak.scalar_f64_divider),
            simd_compute: f32_time(peak.simd_f32, peak.simd_f32_divider)
                + f64_time(peak.simd_f64, peak.simd_f64_divider),
            work,
            bytes_per_joint_frame: bytes,
            peak,
            memory: bytes / substeps_per_frame / bandwidth,
        }
    }

    /// The binding bound: the larger of the SIMD compute line and the memory line.
    pub fn lanes(&self) -> f64 {
        self.simd_compute.max(self.memory)
    }
}

// ---- the report -----------------------------------------------------------------------------------------

/// Per-frame figures read over a few frames after a benchmark.
#[derive(Clone, Copy, Debug)]
pub struct Counters {
    /// Heap allocations (the hot loop should make none).
    pub allocations: f64,
    /// Substeps where the direct inextensibility solve fell back (`Stats::solver_fallbacks`).
    pub solver_fallbacks: f64,
    /// (segment or particle, collider) pairs tested (`Stats::contact_pairs_tested`).
    pub contact_pairs: f64,
    /// Chains the lane solver stepped in the last of those frames (`Stats::lane_chains`).
    pub lane_chains: u32,
}

/// One (scene, variant) benchmark.
#[derive(Clone, Debug)]
pub struct SceneRow {
    pub scene: &'static str,
    pub shape: String,
    pub variant: &'static str,
    pub variant_label: &'static str,
    pub chains: usize,
    pub joints: usize,
    pub dynamic_joints: usize,
    pub substeps: u32,
    pub frame_seconds: Option<f64>,
    pub counters: Option<Counters>,
    /// Why it did not run, when it did not.
    pub missing: Option<String>,
    /// Anything the reader must know about the measurement (e.g. not every chain fell asleep).
    pub note: Option<String>,
}

impl SceneRow {
    pub fn ns_per_joint_substep(&self) -> Option<f64> {
        let work = (self.dynamic_joints as f64) * (self.substeps.max(1) as f64);
        self.frame_seconds.map(|s| s * 1e9 / work)
    }
}

/// One engine on one peer scenario.
#[derive(Clone, Debug)]
pub struct PeerRow {
    pub scenario: String,
    pub engine: String,
    pub substeps_per_frame: usize,
    pub dynamic_joints: usize,
    pub frame_seconds: Option<f64>,
    /// RMS joint error / chain length against the exact pendulum at each call's time over 0.5 s at 60 fps
    /// (pendulums only).
    pub error: Option<f64>,
    pub note: String,
}

/// A skip of SPEC 3.8: a variant against its baseline on one scene.
pub struct Skip {
    pub what: &'static str,
    pub baseline: &'static str,
    pub with: &'static str,
}

pub enum Verdict {
    Met,
    Missed,
    NotMeasured,
}

pub struct Target {
    pub target: String,
    pub measured: String,
    pub verdict: Verdict,
}

impl Target {
    pub fn check(target: &str, measured: String, met: Option<bool>) -> Self {
        let verdict = match met {
            Some(true) => Verdict::Met,
            Some(false) => Verdict::Missed,
            None => Verdict::NotMeasured,
        };
        Self { target: target.into(), measured, verdict }
    }
}

#[derive(Default)]
pub struct Report {
    pub scenes: Vec<SceneRow>,
    pub skips: Vec<Skip>,
    pub ffi: Vec<(String, Option<f64>)>,
    pub paired: Vec<PairedRatio>,
    pub peers: Vec<PeerRow>,
    pub peer_notes: Vec<String>,
    pub targets: Vec<Target>,
    pub notes: Vec<String>,
    /// The plain 1000 x 16 frame against the bound measured round by round with it.
    pub bound_ratio: Option<BoundRatio>,
}

pub fn micros(seconds: Option<f64>) -> String {
    match seconds {
        Some(s) if s * 1e6 >= 100.0 => format!("{:.0}", s * 1e6),
        Some(s) => format!("{:.1}", s * 1e6),
        None => "not run".into(),
    }
}

pub fn ns(value: Option<f64>) -> String {
    value.map_or_else(|| "not run".into(), |v| format!("{v:.0}"))
}

pub fn error(value: Option<f64>) -> String {
    value.map_or_else(|| "-".into(), |v| format!("{v:.2e}"))
}

impl Report {
    pub fn scene(&self, scene: &str, variant: &str) -> Option<&SceneRow> {
        self.scenes.iter().find(|r| r.scene == scene && r.variant == variant)
    }

    pub fn paired(&self, what: &str) -> Option<&PairedRatio> {
        self.paired.iter().find(|p| p.what == what)
    }

    /// The markdown page.
    pub fn markdown(&self, machine: &Machine, simd_path: &str, bound: &Bound, wall: Duration) -> String {
        let mut md = String::new();
        let _ = write!(
            md,
            "# Performance (SPEC 6.3)\n\nGenerated by `cargo bench --bench performance --features peers` \
             (`benches/performance.rs`, scenes in `benches/support/scenes.rs`); do not edit by hand. One thread, \
             release build, default engine settings (240 Hz internal steps: {} substeps per 60 Hz frame, 2 \
             iterations; the lane solver, `Solver::Lanes`, but in the rows marked *scalar solver*). A frame is what a host does at 60 Hz: pose the heads (swaying and turning), per-chain \
             anchors and collider poses, `step_with_anchors`, then `read_world`. Times are medians of criterion's \
             samples, all from one run of {:.0} s. *ns/joint/substep* divides the frame time by the dynamic joints \
             (all but each chain's root) and the substeps.\n\n",
            // The first scene that ran (a filtered run may skip the first ones).
            self.scenes.iter().find(|r| r.missing.is_none()).map_or(4, |r| r.substeps),
            wall.as_secs_f64()
        );
        self.machine_section(&mut md, machine, simd_path);
        self.targets_section(&mut md);
        self.scenes_section(&mut md);
        self.skips_section(&mut md);
        self.ffi_section(&mut md);
        self.linearity_section(&mut md);
        self.peer_section(&mut md);
        self.bound_section(&mut md, bound);
        if !self.notes.is_empty() {
            md.push_str("## Notes\n\n");
            for note in &self.notes {
                let _ = writeln!(md, "- {note}");
            }
        }
        md
    }

    fn machine_section(&self, md: &mut String, machine: &Machine, simd_path: &str) {
        md.push_str("## Machine\n\n| fact | value |\n|---|---|\n");
        let rows = [
            ("CPU model, family and model (/proc/cpuinfo)", machine.cpu_model.clone()),
            (
                "logical CPUs (nproc)",
                format!("{} ({} available to the process)", machine.processors, machine.available_parallelism),
            ),
            ("clock (cpu MHz)", machine.mhz.map_or("unknown".into(), |m| format!("{m:.0} MHz"))),
            ("SIMD features", machine.simd_flags.join(", ")),
            ("L3 cache", machine.l3_cache.clone().unwrap_or_else(|| "unknown".into())),
            ("single-thread stream bandwidth (measured)", format!("{:.1} GB/s", machine.bandwidth / 1e9)),
            (
                "single-thread arithmetic peak (measured: independent multiplies and adds, not fused)",
                format!(
                    "scalar {:.1}; {}-lane SIMD f32 {:.1}, f64 {:.1} G lane operations/s",
                    machine.peak.scalar_f32 / 1e9,
                    machine.peak.lanes,
                    machine.peak.simd_f32 / 1e9,
                    machine.peak.simd_f64 / 1e9
                ),
            ),
            (
                "single-thread divisions and square roots (measured: independent ones)",
                format!(
                    "scalar f32 {:.1} and {:.1}, f64 {:.2} and {:.2}; {}-lane SIMD f32 {:.1} and {:.1}, f64 {:.1} and {:.1} G \
                     lane operations/s",
                    machine.peak.scalar_f32_divider.division / 1e9,
                    machine.peak.scalar_f32_divider.root / 1e9,
                    machine.peak.scalar_f64_divider.division / 1e9,
                    machine.peak.scalar_f64_divider.root / 1e9,
                    machine.peak.lanes,
                    machine.peak.simd_f32_divider.division / 1e9,
                    machine.peak.simd_f32_divider.root / 1e9,
                    machine.peak.simd_f64_divider.division / 1e9,
                    machine.peak.simd_f64_divider.root / 1e9
                ),
            ),
            ("load average at start", machine.load_average.clone().unwrap_or_else(|| "unknown".into())),
            ("compiler", machine.rustc.clone().unwrap_or_else(|| "unknown".into())),
            ("solver path that ran", simd_path.to_owned()),
        ];
        for (fact, value) in rows {
            let _ = writeln!(md, "| {fact} | {value} |");
        }
        md.push('\n');
    }

    fn targets_section(&self, md: &mut String) {
        md.push_str("## Targets\n\n| target | measured | verdict |\n|---|---|---|\n");
        for t in &self.targets {
            let verdict = match t.verdict {
                Verdict::Met => "met",
                Verdict::Missed => "MISSED",
                Verdict::NotMeasured => "not measured yet",
            };
            let _ = writeln!(md, "| {} | {} | {verdict} |", t.target, t.measured);
        }
        md.push('\n');
    }

    fn scenes_section(&self, md: &mut String) {
        md.push_str(
            "## Scenes\n\nCharacters of up to 100 chains (strands on the scalp, 2.5 cm segments, capped at 0.8 m per \
             chain); chains are anchored to their character's head. *views*: 3 view shapes per chain; *colliders*: \
             head sphere and two shoulder capsules per character and a ground plane; *camera still*: the camera \
             rides with the head, so the view direction never changes; *at rest*: heads and camera still, chains \
             settled; *LOD n*: `EngineSettings::lod` (fewer substeps: ns/joint/substep uses the substeps that ran); \
             *scalar solver*: `Engine::set_solver(Solver::Scalar)`, one chain at a time, instead of the default lane \
             solver (equal-length chains side by side in SIMD lanes; the contact pass of chains that may touch a \
             collider screens their segments against spheres and capsules in lanes and resolves each contact in \
             scalar code, lane by lane). \
             Read over 3 frames after each benchmark: heap allocations (a counting allocator), inextensibility \
             solver fallbacks and contact pairs tested (`Stats`), per frame, and the chains the lane solver stepped \
             in the last of them (`Stats::lane_chains`).\n\n\
             | scene | chains x joints | dynamic joints | variant | ns/joint/substep | us/frame | allocs | fallbacks \
             | contact pairs | in lanes |\n\
             |---|---|---|---|---|---|---|---|---|---|\n",
        );
        for r in &self.scenes {
            let counter = |f: fn(&Counters) -> f64| r.counters.as_ref().map_or("-".into(), |c| format!("{:.1}", f(c)));
            let counters = format!(
                "{} | {} | {} | {}",
                counter(|c| c.allocations),
                counter(|c| c.solver_fallbacks),
                counter(|c| c.contact_pairs),
                r.counters.as_ref().map_or("-".into(), |c| c.lane_chains.to_string())
            );
            let time = match &r.missing {
                Some(why) => (why.clone(), why.clone()),
                None => (ns(r.ns_per_joint_substep()), micros(r.frame_seconds)),
            };
            let variant = match &r.note {
                Some(note) => format!("{} ({note})", r.variant_label),
                None => r.variant_label.to_owned(),
            };
            let _ = writeln!(
                md,
                "| {} | {} | {} | {variant} | {} | {} | {counters} |",
                r.scene, r.shape, r.dynamic_joints, time.0, time.1
            );
        }
        md.push('\n');
    }

    fn skips_section(&self, md: &mut String) {
        md.push_str(
            "## What each skip saves (SPEC 3.8)\n\nRatio = frame time with the feature / frame time of the baseline, \
             same scene, same run (criterion medians). Below 1: the variant is cheaper. The last row per scene, \
             where run, is not a skip: the default lane solver against the scalar solver.\n\n\
             | scene | skip | baseline | variant | baseline us/frame | variant us/frame | ratio |\n\
             |---|---|---|---|---|---|---|\n",
        );
        let mut scenes: Vec<&str> = self.scenes.iter().map(|r| r.scene).collect();
        scenes.dedup();
        for scene in scenes {
            for skip in &self.skips {
                let (Some(a), Some(b)) = (self.scene(scene, skip.baseline), self.scene(scene, skip.with)) else {
                    continue;
                };
                let ratio = match (a.frame_seconds, b.frame_seconds) {
                    (Some(x), Some(y)) => format!("{:.2}", y / x),
                    _ => "-".into(),
                };
                let _ = writeln!(
                    md,
                    "| {scene} | {} | {} | {} | {} | {} | {ratio} |",
                    skip.what,
                    a.variant_label,
                    b.variant_label,
                    micros(a.frame_seconds),
                    micros(b.frame_seconds)
                );
            }
        }
        md.push('\n');
        let paired: Vec<_> = self.paired.iter().filter(|p| !p.what.starts_with("C ABI")).collect();
        if !paired.is_empty() {
            md.push_str(
                "Interleaved measurements (blocks of frames of A and B alternate, median over rounds of B / A), for \
                 the ratios that should be 1, what the features cost, and the lane solver against the scalar solver \
                 (B / A below 1: the lane solver is faster):\n\n| what | A | B | A us/frame | B us/frame | B / A | rounds |\n\
                 |---|---|---|---|---|---|---|\n",
            );
            for p in paired {
                paired_row(md, p);
            }
            md.push('\n');
        }
    }

    fn ffi_section(&self, md: &mut String) {
        md.push_str(
            "## C ABI overhead\n\n100 x 16 plain scene built and driven only through the `kdw_*` functions (the \
             ones `include/kodawari.h` declares, called as a C host calls them) against the same frame in Rust. \
             Criterion medians:\n\n| path | us/frame |\n|---|---|\n",
        );
        for (path, seconds) in &self.ffi {
            let _ = writeln!(md, "| {path} | {} |", micros(*seconds));
        }
        let pairs = self.paired.iter().find(|p| p.what.starts_with("C ABI")).map_or(0, |p| p.pairs);
        let _ = write!(
            md,
            "\nInterleaved (the ratio the target uses), each ratio pooled over {pairs} pairs of engines made afresh, with the \
             method's A/A control. Where the allocator puts two engines' arrays shifts one of them by a few percent \
             for its whole life, so a single pair's ratio carries that shift (with one pair, the report of commit \
             b9b8ccf measured the C ABI at +6.0 % and +5.9 %); *pairs* gives the range of the pairs' own \
             medians.\n\n\
             | what | A | B | A us/frame | B us/frame | B / A | rounds | pairs |\n\
             |---|---|---|---|---|---|---|---|\n",
        );
        for p in self.paired.iter().filter(|p| p.what.starts_with("C ABI")) {
            let pairs = p.pair_range.map_or("-".into(), |(low, high)| format!("{low:.3} to {high:.3}"));
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {:.3} | {} | {pairs} |",
                p.what,
                p.a,
                p.b,
                micros(Some(p.a_seconds)),
                micros(Some(p.b_seconds)),
                p.ratio,
                p.rounds
            );
        }
        md.push('\n');
    }

    fn linearity_section(&self, md: &mut String) {
        md.push_str(
            "## Linearity\n\nns/joint/substep of the plain scenes (no view shapes, no colliders) on both solvers, \
             relative to 1000 x 16 on the same solver, and the share of chain-substeps whose direct \
             inextensibility solve fell back (`Stats::solver_fallbacks`; a lone chain takes the scalar solver \
             either way):\n\n",
        );
        md.push_str(
            "| scene | dynamic joints | lanes ns/joint/substep | / 1000 x 16 | scalar ns/joint/substep | / 1000 x 16 | \
             fallbacks |\n|---|---|---|---|---|---|---|\n",
        );
        let per_joint =
            |scene: &str, variant: &str| self.scene(scene, variant).and_then(SceneRow::ns_per_joint_substep);
        let relative = |x: Option<f64>, y: Option<f64>| match (x, y) {
            (Some(x), Some(y)) => format!("{:.2}", x / y),
            _ => "-".into(),
        };
        let (lanes_reference, scalar_reference) = (per_joint("1000x16", "plain"), per_joint("1000x16", "plain_scalar"));
        for r in self.scenes.iter().filter(|r| r.variant == "plain") {
            let lanes = r.ns_per_joint_substep();
            let scalar = per_joint(r.scene, "plain_scalar");
            let fallbacks = r.counters.as_ref().map_or("-".into(), |c| {
                let chain_substeps = (r.chains as f64) * (r.substeps.max(1) as f64);
                format!("{:.0}%", 100.0 * c.solver_fallbacks / chain_substeps)
            });
            let _ = writeln!(
                md,
                "| {} ({}) | {} | {} | {} | {} | {} | {fallbacks} |",
                r.scene,
                r.shape,
                r.dynamic_joints,
                ns(lanes),
                relative(lanes, lanes_reference),
                ns(scalar),
                relative(scalar, scalar_reference),
            );
        }
        md.push('\n');
    }

    fn peer_section(&self, md: &mut String) {
        md.push_str(
            "## Side by side with rapier3d\n\nThe same scenes in rapier3d 0.30 (what a user would pick instead): one \
             rigid body per joint, spherical joints, default `IntegrationParameters` at dt 1/60 s. Pendulum error: \
             RMS joint position error over the dynamic joints and 30 frames (0.5 s at 60 fps) / chain length (1 m), \
             against the exact reference of `benches/support/pendulum.rs` (the accuracy benchmark's), at the time of the \
             call that returned the pose: both engines' poses show that time (kodawari's, at 60 fps, is its newest \
             internal state).\n\n\
             | scenario | engine | substeps/frame | us/frame | ns/joint/substep | RMS error | note |\n\
             |---|---|---|---|---|---|---|\n",
        );
        for p in &self.peers {
            let per_joint =
                p.frame_seconds.map(|s| s * 1e9 / (p.dynamic_joints as f64 * p.substeps_per_frame.max(1) as f64));
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} |",
                p.scenario,
                p.engine,
                p.substeps_per_frame,
                micros(p.frame_seconds),
                ns(per_joint),
                error(p.error),
                p.note
            );
        }
        md.push('\n');
        for note in &self.peer_notes {
            let _ = writeln!(md, "- {note}");
        }
        if !self.peer_notes.is_empty() {
            md.push('\n');
        }
    }

    fn bound_section(&self, md: &mut String, bound: &Bound) {
        // The plain variant runs the default lane solver; `plain_scalar` the same scene on the scalar solver.
        let measured = self.scene("1000x16", "plain").and_then(SceneRow::ns_per_joint_substep);
        let measured_scalar = self.scene("1000x16", "plain_scalar").and_then(SceneRow::ns_per_joint_substep);
        let _ = write!(
            md,
            "## Lower bound for 1000 x 16\n\nOperations per dynamic joint per substep, counted from the lane kernel's \
             code at default settings (add, subtract, multiply, divide, square root = 1; where the code iterates to a \
             tolerance the minimum it runs is counted, so this is a lower bound for the algorithm as written; the \
             count is itemised in `benches/support/perf_report.rs`). Among them the divisions and square roots, which \
             the bound prices at their own measured rates:\n\n\
             | part | f32 operations | f64 operations | of which f32 divisions, square roots | f64 divisions, square \
             roots |\n|---|---|---|---|---|\n"
        );
        for w in SUBSTEP_WORK.iter().chain([&bound.work]) {
            let _ = writeln!(
                md,
                "| {} | {:.0} | {:.0} | {}, {} | {}, {} |",
                w.part, w.f32_operations, w.f64_operations, w.f32_divisions, w.f32_roots, w.f64_divisions, w.f64_roots
            );
        }
        md.push('\n');
        md.push_str(
            "Bytes per joint per frame streamed from memory when the scene does not fit in cache (a chain's substeps \
             run back to back, so its data is loaded once per frame):\n\n| data | bytes |\n|---|---|\n",
        );
        for (part, n) in FRAME_BYTES {
            let _ = writeln!(md, "| {part} | {n:.0} |");
        }
        let _ = writeln!(md, "| total | {:.0} |\n", bound.bytes_per_joint_frame);
        let ratio = |measured: Option<f64>, b: f64| measured.map_or("-".into(), |m| format!("{:.1}", m / (b * 1e9)));
        let peak = &bound.peak;
        let _ = write!(
            md,
            "The compute lines run the operations at this core's measured peaks (the machine table): independent \
             multiplies and adds, never fused, since the kernel's determinism policy rules out fused multiply-adds; \
             divisions and square roots at the divider's measured rates (the reports up to commit f5958c3 priced them \
             like multiplies, a rate no divider reaches: the SIMD line was 23.6 ns there); \
             single- and double-precision operations each at their own rate.\n\n\
             | bound (per joint per substep) | ns | lane solver (plain): measured / bound \
             | scalar solver (plain, scalar solver): measured / bound |\n|---|---|---|---|\n\
             | compute, scalar peak ({:.1} G operations/s) | {:.1} | {} | {} |\n\
             | compute, {}-lane SIMD peak (f32 {:.1}, f64 {:.1} G lane operations/s; the widest kernel that ran) \
             | {:.1} | {} | - |\n\
             | memory, measured stream bandwidth | {:.1} | {} | {} |\n\n\
             Measured (1000 x 16): lane solver (the default; the plain variant) {} ns/joint/substep, scalar solver \
             {} ns/joint/substep. The lane solver is bounded by the SIMD line, the scalar solver by the scalar one. \
             The 1000 x 16 working set (about {:.1} MB) fits in the L3 cache, so the memory line bounds the 16384 x \
             16 scene rather than this one; compute is the binding bound.\n\n",
            peak.scalar_f32 / 1e9,
            bound.scalar_compute * 1e9,
            ratio(measured, bound.scalar_compute),
            ratio(measured_scalar, bound.scalar_compute),
            peak.lanes,
            peak.simd_f32 / 1e9,
            peak.simd_f64 / 1e9,
            bound.simd_compute * 1e9,
            ratio(measured, bound.simd_compute),
            bound.memory * 1e9,
            ratio(measured, bound.memory),
            ratio(measured_scalar, bound.memory),
            ns(measured),
            ns(measured_scalar),
            16_000.0 * WORKING_SET_BYTES_PER_JOINT / 1e6,
        );
        if let Some(b) = &self.bound_ratio {
            let _ = write!(
                md,
                "Measured with the bound: the ratios above divide frame medians by a bound whose peaks were \
                 measured once, before the scenes, at whatever clock the core ran then. Measured together, round \
                 by round (the peaks, best of two passes each, then the median of a block of 1000 x 16 plain \
                 frames, or the other way round; {} rounds), the lane solver took {:.0} ns/joint/substep against a \
                 bound of {:.1} (medians; the rounds' bounds ranged from {:.1} to {:.1}): **{:.1}x**, the median of the rounds' \
                 own ratios. The target's verdict uses this ratio.\n\n",
                b.rounds,
                b.measured * 1e9,
                b.bound * 1e9,
                b.bound_range.0 * 1e9,
                b.bound_range.1 * 1e9,
                b.ratio,
            );
        }
    }
}

fn paired_row(md: &mut String, p: &PairedRatio) {
    let _ = writeln!(
        md,
        "| {} | {} | {} | {} | {} | {:.3} | {} |",
        p.what,
        p.a,
        p.b,
        micros(Some(p.a_seconds)),
        micros(Some(p.b_seconds)),
        p.ratio,
        p.rounds
    );
}
