//! Performance evidence (SPEC 6.3): cost per joint per internal substep and per 60 Hz frame on named scenes,
//! what each skip of SPEC 3.8 saves, the lane solver against the scalar solver, the C ABI's overhead,
//! linearity in the joint count, and rapier3d side by side on the same scenes and on the accuracy benchmark's
//! pendulums.
//!
//! `cargo bench --bench performance --features peers` runs it all (criterion groups, then interleaved
//! ratio measurements) and writes `docs/performance.md`. Without `--features peers` the rapier3d rows say the
//! peer was skipped. Under `cargo test --benches` criterion runs every benchmark once and nothing is written.
//! With a criterion filter the report is partial and goes to `target/performance-partial.md` instead.
//!
//! Single thread, default engine settings (so the lane solver, but in the scalar-solver variants). Times are
//! criterion's medians (see `perf_report::Recorder`); the ratios that should come out at 1 (C ABI, features a
//! chain does not use) and the lane solver's speed-up are measured interleaved, so a change of load on the
//! shared machine cannot fake or hide a difference.

#[path = "support/peak.rs"]
mod peak;
#[path = "support/peer_pendulum.rs"]
mod peer_pendulum;
#[cfg(feature = "peers")]
#[path = "support/peer_rapier.rs"]
mod peer_rapier;
#[path = "support/pendulum.rs"]
mod pendulum;
#[path = "support/perf_report.rs"]
mod perf_report;
#[path = "support/scene_ffi.rs"]
mod scene_ffi;
#[path = "support/scenes.rs"]
mod scenes;

use std::fmt::Write as _;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{BenchmarkGroup, Criterion, SamplingMode, measurement::WallTime};
use peer_pendulum::{KodawariPendulum, Reference};
use perf_report::{
    Bound, BoundRatio, Counting, Machine, PairedRatio, PeerRow, Recorder, Report, SceneRow, Skip, Target,
    interleaved_bound_ratio, micros, paired_ratio, pooled_paired_ratio,
};
use scene_ffi::{FfiFrame, FfiSceneRun};
use scenes::{
    ASLEEP, AWAKE_AT_REST, COLLIDERS, COLLIDERS_SCALAR, CameraMotion, DISABLED, LIMP, LOD1, LOD2, MASKED_COLLIDERS,
    PLAIN, PLAIN_SCALAR, PLAIN_STILL, ReadBack, Scene, SceneRun, VIEWS, VIEWS_COLLIDERS, VIEWS_STILL, Variant,
};

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The solver path that ran: the lane solver (the default) with the kernel `kodawari::simd_path` reports for
/// this CPU (how the contact pass runs), and the scalar solver for the few left over from the lane groups.
fn solver_path() -> String {
    const NEAR_COLLIDERS: &str = "contacts against spheres and capsules screened in lanes (groups of 8 with AVX2), \
                                  each contact resolved in scalar code, lane by lane; the last 1 or 2 chains of a \
                                  joint count after its full groups (too few for a group): scalar solver";
    let lanes = "lane solver (chains of equal joint count in SIMD groups of 16, 8 or 4)";
    match kodawari::simd_path() {
        "avx512" => format!(
            "{lanes}, kernels chosen at run time: avx512 for groups of 16, avx2 for groups of 8 and 4; {NEAR_COLLIDERS}"
        ),
        "avx2" => {
            format!("{lanes}, avx2 kernel chosen at run time (no AVX-512 here: no groups of 16); {NEAR_COLLIDERS}")
        }
        "sse2" => format!("{lanes}, sse2 kernel (the portable x86-64 copy: no AVX2 on this CPU); {NEAR_COLLIDERS}"),
        "scalar" => {
            format!("{lanes}, no SIMD instructions on this architecture (lanes in scalar code); {NEAR_COLLIDERS}")
        }
        path => format!("{lanes}, {path} kernel; {NEAR_COLLIDERS}"),
    }
}

const SCENES: [Scene; 7] = [
    Scene::uniform("1x8", 1, 8),
    Scene::uniform("100x16", 100, 16),
    Scene::uniform("1000x16", 1000, 16),
    // Far beyond the caches: about 60 MB of chain data.
    Scene::uniform("16384x16", 16384, 16),
    Scene::uniform("1x256", 1, 256),
    Scene::uniform("1x1000", 1, 1000),
    Scene::ragged("ragged", 200, 4, 32),
];

/// Linearity: one chain of 1000 hair segments (2.5 cm, a 25 m rope), the same segment as the 16-joint
/// scenes, so that its per-joint cost shows the solver's scaling rather than the fine rope's regime (the
/// 0.8 m `1x1000` rope's 0.8 mm segments make the direct inextensibility solve fall back: bug 1 in
/// docs/robustness.md). Plain variant only, on both solvers.
const LINEARITY_SCENE: Scene = Scene::uniform("1x1000_hair", 1, 1000).with_segment(0.025);

/// Every scene runs these variants (one line per variant).
const VARIANTS: [Variant; 5] = [PLAIN, VIEWS, VIEWS_STILL, COLLIDERS, VIEWS_COLLIDERS];
/// Scenes that also run the plain variant on the scalar solver, next to the (default) lane solver.
const SCALAR_SCENES: [&str; 5] = ["100x16", "1000x16", "1x256", "1x1000", "ragged"];
/// Controls ("a chain pays nothing for features it does not use") and the per-chain skips, on the 100 x 16
/// scene only.
const CONTROLS_SCENE: &str = "100x16";
const CONTROLS: [Variant; 7] = [PLAIN_STILL, MASKED_COLLIDERS, AWAKE_AT_REST, ASLEEP, DISABLED, LOD1, LOD2];

/// The skips of SPEC 3.8 as (variant against baseline) pairs.
const SKIPS: [Skip; 10] = [
    Skip { what: "no view shapes", baseline: "views", with: "plain" },
    Skip { what: "camera direction unchanged", baseline: "views", with: "views_still" },
    Skip { what: "no colliders", baseline: "colliders", with: "plain" },
    Skip { what: "colliders not in the chain's mask", baseline: "plain", with: "colliders_masked" },
    Skip { what: "camera still, chain without view shapes", baseline: "plain", with: "plain_still" },
    Skip { what: "chain asleep", baseline: "awake_at_rest", with: "asleep" },
    Skip { what: "chain disabled", baseline: "plain", with: "disabled" },
    Skip { what: "level of detail 1", baseline: "plain", with: "lod1" },
    Skip { what: "level of detail 2", baseline: "plain", with: "lod2" },
    // Not a skip of SPEC 3.8, but read the same way: the lane solver's frame against the scalar solver's.
    Skip { what: "lane solver instead of the scalar solver", baseline: "plain_scalar", with: "plain" },
];

/// Interleaved rounds for the ratios that should be 1, and the length of each block of frames.
const PAIRED_ROUNDS: usize = 40;
const PAIRED_BLOCK: Duration = Duration::from_millis(25);

/// How long criterion samples a benchmark, by the work of one frame: small scenes get many samples, the
/// 16384-chain scene (about half a second per frame) the minimum criterion accepts.
struct Budget {
    sample_size: usize,
    warm_up: Duration,
    measurement: Duration,
}

fn budget(dynamic_joints: usize) -> Budget {
    let ms = Duration::from_millis;
    match dynamic_joints {
        0..=5_000 => Budget { sample_size: 20, warm_up: ms(400), measurement: ms(1200) },
        5_001..=50_000 => Budget { sample_size: 15, warm_up: ms(300), measurement: ms(2000) },
        _ => Budget { sample_size: 10, warm_up: ms(100), measurement: ms(4000) },
    }
}

/// Runs frames after building a scene so the chains are in motion before anything is timed: about
/// `PREROLL` of wall time, at least 2 and at most 60 frames (the big scenes and rapier's multibodies take
/// seconds per frame and must not spend their budget here).
/// Returns the seconds the last frame took.
fn preroll(mut frame: impl FnMut()) -> f64 {
    const PREROLL: Duration = Duration::from_millis(300);
    let timed = |frame: &mut dyn FnMut()| {
        let start = Instant::now();
        frame();
        start.elapsed().as_secs_f64()
    };
    let first = timed(&mut frame);
    let frames = (PREROLL.as_secs_f64() / first.max(1e-9)).clamp(2.0, 60.0) as u32;
    let mut last = first;
    for _ in 1..frames {
        last = timed(&mut frame);
    }
    last
}

/// The budget for a benchmark whose frame takes about `frame_seconds`: as [`budget`] for frames up to
/// 0.1 s, then criterion's minimum of 10 samples of one frame each. (Only the rapier scene needs it.)
#[cfg(feature = "peers")]
fn budget_for_frame(frame_seconds: f64) -> Budget {
    match frame_seconds {
        f if f < 0.005 => budget(0),
        f if f < 0.1 => budget(10_000),
        f => Budget {
            sample_size: 10,
            warm_up: Duration::from_millis(100),
            measurement: Duration::from_secs_f64(10.0 * f),
        },
    }
}

fn configure(group: &mut BenchmarkGroup<'_, WallTime>, budget: &Budget) {
    group.sample_size(budget.sample_size);
    group.warm_up_time(budget.warm_up);
    group.measurement_time(budget.measurement);
    // Every sample runs the same number of frames: the frames are long and the machine is shared.
    group.sampling_mode(SamplingMode::Flat);
}

/// Whether this is a real `cargo bench` run (as criterion decides: `--bench` without `--test` or `--list`).
fn is_benchmark_run() -> bool {
    let args: Vec<String> = std::env::args().collect();
    let has = |flag: &str| args.iter().any(|a| a == flag);
    has("--bench") && !has("--test") && !has("--list")
}

// ---- scenes ------------------------------------------------------------------------------------------

fn bench_scene(criterion: &mut Criterion, recorder: &Recorder, report: &mut Report, scene: &Scene, variant: Variant) {
    let budget = budget(scene.dynamic_joints());
    let group_name = format!("scene_{}", scene.name);
    let id = format!("{group_name}/{}", variant.id);
    let mut group = criterion.benchmark_group(&group_name);
    configure(&mut group, &budget);
    // Built on first use, so a criterion filter that skips the benchmark also skips building the scene.
    let mut run: Option<Result<SceneRun, String>> = None;
    let mut note = None;
    group.bench_function(variant.id, |b| {
        let built = run.get_or_insert_with(|| {
            let mut built = SceneRun::new(scene, variant, ReadBack::World).map_err(|e| e.to_string())?;
            let _ = preroll(|| built.frame());
            note = built.settle();
            Ok(built)
        });
        match built {
            Ok(r) => b.iter_custom(|iters| recorder.time(&id, iters, || r.frame())),
            // Keep criterion's loop going without timing anything; the report says why.
            Err(_) => b.iter_custom(|_| Duration::from_nanos(1)),
        }
    });
    group.finish();
    let mut counters = None;
    let (frame_seconds, substeps, _allocations, missing) = match &mut run {
        Some(Ok(r)) => {
            let before = r.engine.stats();
            let allocations = perf_report::allocations_per_frame(CHECK_FRAMES, || r.frame());
            let after = r.engine.stats();
            counters = Some(perf_report::Counters {
                allocations,
                solver_fallbacks: (after.solver_fallbacks - before.solver_fallbacks) as f64 / CHECK_FRAMES as f64,
                contact_pairs: (after.contact_pairs_tested - before.contact_pairs_tested) as f64 / CHECK_FRAMES as f64,
                lane_chains: after.lane_chains,
            });
            (recorder.median_frame(&id, budget.sample_size), r.substeps_last_frame(), Some(allocations), None)
        }
        Some(Err(e)) => {
            println!("{id}: could not build the scene: {e}");
            (None, 0, None, Some(format!("not built: {e}")))
        }
        None => (None, 0, None, Some(FILTERED_OUT.into())),
    };
    report.scenes.push(SceneRow {
        scene: scene.name,
        shape: scene.shape_label(),
        variant: variant.id,
        variant_label: variant.label,
        chains: scene.chains,
        joints: scene.total_joints(),
        dynamic_joints: scene.dynamic_joints(),
        substeps,
        frame_seconds,
        counters,
        missing,
        note,
    });
}

/// Frames after a scene's benchmark over which allocations and engine counters are read.
const CHECK_FRAMES: u32 = 3;

const FILTERED_OUT: &str = "not run (filtered out)";

fn bench_scenes(criterion: &mut Criterion, recorder: &Recorder, report: &mut Report) {
    for scene in &SCENES {
        for variant in VARIANTS {
            bench_scene(criterion, recorder, report, scene, variant);
        }
        if SCALAR_SCENES.contains(&scene.name) {
            bench_scene(criterion, recorder, report, scene, PLAIN_SCALAR);
        }
        if scene.name == CONTROLS_SCENE {
            for variant in CONTROLS {
                bench_scene(criterion, recorder, report, scene, variant);
            }
        }
        if scene.name == PEER_SCENE {
            bench_scene(criterion, recorder, report, scene, LIMP);
        }
    }
    bench_scene(criterion, recorder, report, &LINEARITY_SCENE, PLAIN);
    bench_scene(criterion, recorder, report, &LINEARITY_SCENE, PLAIN_SCALAR);
    report.skips.extend(SKIPS);
}

/// Skips measured interleaved on the 100 x 16 scene (baseline A, variant B), with an A/A control: two
/// identical engines, whose ratio shows the noise floor of the method on this machine.
const INTERLEAVED: [(&str, Variant, Variant); 7] = [
    (NOISE_FLOOR, PLAIN, PLAIN),
    (CAMERA_IGNORED, PLAIN_STILL, PLAIN),
    (MASK_IGNORED, PLAIN, MASKED_COLLIDERS),
    ("100 x 16: view shapes with an orbiting camera vs none", PLAIN, VIEWS),
    ("100 x 16: view shapes, camera still vs orbiting", VIEWS, VIEWS_STILL),
    ("100 x 16: colliders vs none", PLAIN, COLLIDERS),
    ("100 x 16: asleep vs awake at rest", AWAKE_AT_REST, ASLEEP),
];
const NOISE_FLOOR: &str = "100 x 16 A/A control: two identical plain engines";
const CAMERA_IGNORED: &str = "100 x 16 without view shapes: orbiting camera vs camera still";
const MASK_IGNORED: &str = "100 x 16: colliders in the engine but in no chain's mask vs no colliders";

/// The lane solver (B, the default) against the scalar solver (A), interleaved: (what, scene, A, B, rounds,
/// block). A 1000 x 16 frame takes tens of milliseconds, so there fewer, longer blocks.
const SOLVER_PAIRS: [(&str, &str, Variant, Variant, usize, Duration); 4] = [
    (LANES_100, "100x16", PLAIN_SCALAR, PLAIN, PAIRED_ROUNDS, PAIRED_BLOCK),
    (LANES_1000, "1000x16", PLAIN_SCALAR, PLAIN, 20, Duration::from_millis(100)),
    (LANES_100_COLLIDERS, "100x16", COLLIDERS_SCALAR, COLLIDERS, PAIRED_ROUNDS, PAIRED_BLOCK),
    (LANES_1000_COLLIDERS, "1000x16", COLLIDERS_SCALAR, COLLIDERS, 20, Duration::from_millis(100)),
];
const LANES_100: &str = "100 x 16: lane solver vs scalar solver";
const LANES_1000: &str = "1000 x 16: lane solver vs scalar solver";
const LANES_100_COLLIDERS: &str = "100 x 16 with colliders: lane solver vs scalar solver";
const LANES_1000_COLLIDERS: &str = "1000 x 16 with colliders: lane solver vs scalar solver";

/// Linearity on the scalar solver, interleaved (what, long scene, many-chain scene): the per-joint cost of one
/// chain of 1000 joints against 1000 chains of 16, as a ratio of frame times (A: 1000 x 16, B: the long chain)
/// scaled by their dynamic joints. Separate criterion medians taken minutes apart moved this ratio by a third
/// with the machine's load alone: 1.19 in one run, 1.63 in the next, whose builds executed the same
/// instructions on both scenes within 0.03 % (callgrind, `scene_cost 60 {1x1000,100x16} scalar`).
const LINEARITY_PAIRS: [(&str, &str); 2] = [(LINEARITY_ROPE, "1x1000"), (LINEARITY_HAIR, LINEARITY_SCENE.name)];
const LINEARITY_ROPE: &str = "scalar solver: 1 x 1000 (0.8 m rope) vs 1000 x 16";
const LINEARITY_HAIR: &str = "scalar solver: 1 x 1000 (hair segments) vs 1000 x 16";
/// The per-joint cost ratios the linearity target accepts (1 x 1000 against 1000 x 16, either way).
const LINEARITY_BAR: std::ops::RangeInclusive<f64> = 1.0 / 1.5..=1.5;

fn find_scene(scene_name: &str) -> &'static Scene {
    SCENES.iter().chain([&LINEARITY_SCENE]).find(|s| s.name == scene_name).expect("the scene is listed")
}

fn build_settled(scene_name: &str, variant: Variant) -> SceneRun {
    let scene = find_scene(scene_name);
    let mut run = SceneRun::new(scene, variant, ReadBack::World).expect("the scene builds");
    let _ = preroll(|| run.frame());
    let _ = run.settle();
    run
}

fn interleaved_skips(report: &mut Report) {
    for (what, a, b) in INTERLEAVED {
        let (mut run_a, mut run_b) = (build_settled(CONTROLS_SCENE, a), build_settled(CONTROLS_SCENE, b));
        report.paired.push(paired_ratio(
            what,
            (a.label, &mut || run_a.frame()),
            (b.label, &mut || run_b.frame()),
            PAIRED_ROUNDS,
            PAIRED_BLOCK,
        ));
    }
    for (what, long) in LINEARITY_PAIRS {
        let (mut run_a, mut run_b) = (build_settled("1000x16", PLAIN_SCALAR), build_settled(long, PLAIN_SCALAR));
        report.paired.push(paired_ratio(
            what,
            ("1000 x 16", &mut || run_a.frame()),
            ("1 x 1000", &mut || run_b.frame()),
            20,
            Duration::from_millis(100),
        ));
    }
    for (what, scene, a, b, rounds, block) in SOLVER_PAIRS {
        let (mut run_a, mut run_b) = (build_settled(scene, a), build_settled(scene, b));
        report.paired.push(paired_ratio(
            what,
            (a.label, &mut || run_a.frame()),
            (b.label, &mut || run_b.frame()),
            rounds,
            block,
        ));
    }
}

/// Rounds of [`bound_ratio`]: each a pass of the peak probes (about 20 ms) and a block of frames.
const BOUND_ROUNDS: usize = 21;

/// The plain 1000 x 16 frame against the bound, measured round by round together (`interleaved_bound_ratio`).
fn bound_ratio(machine: &Machine) -> BoundRatio {
    let mut run = build_settled("1000x16", PLAIN);
    let dynamic_joints = find_scene("1000x16").dynamic_joints() as f64;
    let mut frame = || {
        run.frame();
        run.substeps_last_frame()
    };
    interleaved_bound_ratio(&mut frame, dynamic_joints, machine.bandwidth, BOUND_ROUNDS, Duration::from_millis(100))
}

// ---- C ABI -------------------------------------------------------------------------------------------

const FFI_SCENE: Scene = Scene::uniform("100x16", 100, 16);

fn bench_ffi(criterion: &mut Criterion, recorder: &Recorder, report: &mut Report) {
    let budget = budget(FFI_SCENE.dynamic_joints());
    let mut group = criterion.benchmark_group("c_abi_100x16");
    configure(&mut group, &budget);
    let mut rust_rotations = SceneRun::new(&FFI_SCENE, PLAIN, ReadBack::LocalRotations).expect("scene builds");
    let mut rust_world = SceneRun::new(&FFI_SCENE, PLAIN, ReadBack::World).expect("scene builds");
    let mut c_one_call = FfiSceneRun::new(&FFI_SCENE, 0, CameraMotion::Orbit, FfiFrame::StepAndRead);
    let mut c_three_calls = FfiSceneRun::new(&FFI_SCENE, 0, CameraMotion::Orbit, FfiFrame::SetAnchorsStepReadWorld);
    let paths: [(&str, &str, &mut dyn FnMut()); 4] = [
        ("rust_step_read_local", "Rust: step_with_anchors + read_local_rotations", &mut || rust_rotations.frame()),
        ("c_step_and_read", "C: kdw_engine_step_and_read (one call)", &mut || c_one_call.frame()),
        ("rust_step_read_world", "Rust: step_with_anchors + read_world", &mut || rust_world.frame()),
        (
            "c_set_anchors_step_read_world",
            "C: kdw_engine_set_anchors + kdw_engine_step + kdw_engine_read_world",
            &mut || c_three_calls.frame(),
        ),
    ];
    for (id, label, frame) in paths {
        let key = format!("c_abi_100x16/{id}");
        group.bench_function(id, |b| b.iter_custom(|iters| recorder.time(&key, iters, &mut *frame)));
        report.ffi.push((label.to_owned(), recorder.median_frame(&key, budget.sample_size)));
    }
    group.finish();
}

/// Fresh pairs of engines each C ABI ratio pools (`pooled_paired_ratio`). Where the allocator puts a pair's
/// arrays moves its own ratio by up to a quarter on this machine (the A/A control's pairs ranged 0.950 to 1.270
/// in stop 44's report, with 16 pairs, whose pooled one-call ratio came out +0.6 % and +5.3 % in two runs of the
/// same C ABI code): 64 pairs of 2 rounds each halve that spread for a few seconds more.
const FFI_PAIRS: usize = 64;
const FFI_NOISE_FLOOR: &str = "C ABI method's A/A control: two Rust engines, step_with_anchors + read_local_rotations";

fn ffi_ratios(report: &mut Report) {
    let rust = |read_back: ReadBack| {
        move || -> Box<dyn FnMut()> {
            let mut run = SceneRun::new(&FFI_SCENE, PLAIN, read_back).expect("scene builds");
            Box::new(move || run.frame())
        }
    };
    let c = |mode: FfiFrame| {
        move || -> Box<dyn FnMut()> {
            let mut run = FfiSceneRun::new(&FFI_SCENE, 0, CameraMotion::Orbit, mode);
            Box::new(move || run.frame())
        }
    };
    let ratios = [
        (
            FFI_NOISE_FLOOR,
            ("Rust step_with_anchors + read_local_rotations", &rust(ReadBack::LocalRotations) as &dyn Fn() -> _),
            ("the same, a second engine", &rust(ReadBack::LocalRotations) as &dyn Fn() -> _),
        ),
        (
            "C ABI, one call per frame (Unity path)",
            ("Rust step_with_anchors + read_local_rotations", &rust(ReadBack::LocalRotations)),
            ("C kdw_engine_step_and_read", &c(FfiFrame::StepAndRead)),
        ),
        (
            "C ABI, three calls per frame",
            ("Rust step_with_anchors + read_world", &rust(ReadBack::World)),
            ("C set_anchors + step + read_world", &c(FfiFrame::SetAnchorsStepReadWorld)),
        ),
    ];
    for (what, a, b) in ratios {
        report.paired.push(pooled_paired_ratio(what, a, b, FFI_PAIRS, 2 * FFI_PAIRS, PAIRED_BLOCK));
    }
}

// ---- the peer ----------------------------------------------------------------------------------------

const PEER_SCENE: &str = "1000x16";
const PENDULUM_JOINTS: [usize; 2] = [3, 9];

/// Which rapier3d variants this build can run.
#[cfg(feature = "peers")]
const RAPIER: [peer_rapier::JointSolver; 2] = [peer_rapier::JointSolver::Impulse, peer_rapier::JointSolver::Multibody];

#[cfg(feature = "peers")]
fn rapier_id(solver: peer_rapier::JointSolver) -> &'static str {
    match solver {
        peer_rapier::JointSolver::Impulse => "rapier_impulse",
        peer_rapier::JointSolver::Multibody => "rapier_multibody",
    }
}

fn bench_pendulums(criterion: &mut Criterion, recorder: &Recorder, report: &mut Report) {
    for joints in PENDULUM_JOINTS {
        let reference = Reference::new(joints);
        let group_name = format!("pendulum_{}_joints", joints);
        let budget = budget(joints);
        let mut group = criterion.benchmark_group(&group_name);
        configure(&mut group, &budget);

        let error = peer_pendulum::kodawari_error(&reference);
        let mut run = KodawariPendulum::new(joints);
        let key = format!("{group_name}/kodawari");
        group.bench_function("kodawari", |b| b.iter_custom(|iters| recorder.time(&key, iters, || run.frame())));
        report.peers.push(PeerRow {
            scenario: reference.name(),
            engine: "kodawari (default settings)".into(),
            substeps_per_frame: run.engine.stats().substeps_last_step as usize,
            dynamic_joints: joints - 1,
            frame_seconds: recorder.median_frame(&key, budget.sample_size),
            error: Some(error),
            note: "stiffness 0, damping 0".into(),
        });

        #[cfg(feature = "peers")]
        for solver in RAPIER {
            let error = peer_rapier::rapier_error(&reference, solver);
            let mut run = peer_rapier::RapierPendulum::new(joints, peer_pendulum::ROOT, solver);
            let key = format!("{group_name}/{}", rapier_id(solver));
            group.bench_function(rapier_id(solver), |b| {
                b.iter_custom(|iters| recorder.time(&key, iters, || run.frame()))
            });
            report.peers.push(PeerRow {
                scenario: reference.name(),
                engine: solver.label().into(),
                substeps_per_frame: run.world.substeps(),
                dynamic_joints: joints - 1,
                frame_seconds: recorder.median_frame(&key, budget.sample_size),
                error: Some(error),
                note: format!("ball inertia r = {} m", peer_rapier::BALL_RADIUS),
            });
        }
        group.finish();
    }
}

fn bench_peer_scene(criterion: &mut Criterion, recorder: &Recorder, report: &mut Report) {
    let scene = *SCENES.iter().find(|s| s.name == PEER_SCENE).expect("the peer scene is listed");
    if let Some(row) = report.scene(PEER_SCENE, PLAIN.id) {
        report.peers.push(PeerRow {
            scenario: format!("{} hair scene", scene.shape_label()),
            engine: "kodawari (default settings)".into(),
            substeps_per_frame: row.substeps as usize,
            dynamic_joints: scene.dynamic_joints(),
            frame_seconds: row.frame_seconds,
            error: None,
            note: "the plain variant above (bending stiffness 0.5)".into(),
        });
    }
    if let Some(row) = report.scene(PEER_SCENE, LIMP.id) {
        report.peers.push(PeerRow {
            scenario: format!("{} hair scene", scene.shape_label()),
            engine: "kodawari, limp chains".into(),
            substeps_per_frame: row.substeps as usize,
            dynamic_joints: scene.dynamic_joints(),
            frame_seconds: row.frame_seconds,
            error: None,
            note: "stiffness 0: like for like with rapier's chains".into(),
        });
    }
    #[cfg(feature = "peers")]
    {
        let mut group = criterion.benchmark_group(format!("peer_{PEER_SCENE}"));
        for solver in RAPIER {
            let mut run = peer_rapier::RapierScene::new(&scene, solver);
            let budget = budget_for_frame(preroll(|| run.frame()));
            configure(&mut group, &budget);
            let key = format!("peer_{PEER_SCENE}/{}", rapier_id(solver));
            group.bench_function(rapier_id(solver), |b| {
                b.iter_custom(|iters| recorder.time(&key, iters, || run.frame()))
            });
            let reach = run.worst_reach();
            report.peers.push(PeerRow {
                scenario: format!("{} hair scene", scene.shape_label()),
                engine: solver.label().into(),
                substeps_per_frame: run.world.substeps(),
                dynamic_joints: scene.dynamic_joints(),
                frame_seconds: recorder.median_frame(&key, budget.sample_size),
                error: None,
                note: format!("limp (no bending stiffness); farthest body / chain length {reach:.2}"),
            });
        }
        group.finish();
        report.peer_notes.push(format!(
            "rapier3d: `IntegrationParameters::default()` (dt 1/60 s, `num_solver_iterations` {}: rapier divides each \
             step into that many substeps, 1/240 s, the same internal rate as kodawari's default), one \
             `PhysicsPipeline::step` per frame, f32, no colliders, sleeping off, each body the inertia of a {} m \
             ball (rapier has no point masses). The hair scene's roots are kinematic bodies following the heads.",
            peer_rapier::default_substeps(),
            peer_rapier::BALL_RADIUS
        ));
    }
    #[cfg(not(feature = "peers"))]
    {
        let _ = (criterion, recorder);
        println!("peer: rapier3d skipped (build with --features peers)");
        report.peer_notes.push("rapier3d skipped: this run was built without `--features peers`.".into());
    }
}

// ---- targets -----------------------------------------------------------------------------------------

fn ns_per_joint(report: &Report, scene: &str, variant: &str) -> Option<f64> {
    report.scene(scene, variant).and_then(SceneRow::ns_per_joint_substep)
}

fn targets(report: &Report, bound: &Bound) -> Vec<Target> {
    let mut out = Vec::new();

    let plain = report.scene("1000x16", PLAIN.id);
    let frame = plain.and_then(|r| r.frame_seconds);
    let everything = report.scene("1000x16", VIEWS_COLLIDERS.id).and_then(|r| r.frame_seconds);
    out.push(Target::check(
        "1000 x 16 joints <= 1 ms per 60 Hz frame",
        format!("{} us plain ({} us with view shapes and colliders)", micros(frame), micros(everything)),
        frame.map(|s| s <= 1e-3),
    ));
    let over_bound = plain.and_then(SceneRow::ns_per_joint_substep).map(|ns| ns / (bound.lanes() * 1e9));
    let separate = over_bound.map_or("not run".into(), |r| {
        format!(
            "{r:.1}x the bound of {:.1} ns/joint/substep from the separate measurements (operations counted, at the \
             measured peaks of the multipliers and adders and of the divider)",
            bound.lanes() * 1e9
        )
    });
    let (measured, verdict) = match &report.bound_ratio {
        Some(b) => (
            format!(
                "{:.1}x measured with the bound, round by round (median of {} rounds: {:.0} against {:.1} ns/joint/substep); \
                 {separate}",
                b.ratio,
                b.rounds,
                b.measured * 1e9,
                b.bound * 1e9
            ),
            Some(b.ratio <= 3.0),
        ),
        None => (separate, over_bound.map(|r| r <= 3.0)),
    };
    out.push(Target::check(
        "1000 x 16 within 3x of the compute / memory bound (the lower bound section)",
        measured,
        verdict,
    ));

    let asleep = report.scene(CONTROLS_SCENE, ASLEEP.id).filter(|r| r.note.is_none()).and_then(|r| r.frame_seconds);
    let awake = report.scene(CONTROLS_SCENE, AWAKE_AT_REST.id).and_then(|r| r.frame_seconds);
    let sleep_ratio = asleep.zip(awake).map(|(a, b)| a / b);
    out.push(Target::check(
        "a sleeping chain costs <= 2% of an active one",
        match (sleep_ratio, asleep, awake) {
            (Some(r), Some(a), Some(b)) => format!(
                "100 x 16 asleep {} us vs awake at rest {} us per frame: {:.1}%",
                micros(Some(a)),
                micros(Some(b)),
                r * 100.0
            ),
            _ => "not run, or not every chain fell asleep (see the scene table)".into(),
        },
        sleep_ratio.map(|r| r <= 0.02),
    ));

    // "Pays nothing": within the noise of an interleaved measurement on this machine.
    const NOTHING: f64 = 1.03;
    let camera = report.paired(CAMERA_IGNORED);
    let masked = report.paired(MASK_IGNORED);
    let floor = report.paired(NOISE_FLOOR);
    let worst = [camera, masked]
        .iter()
        .flatten()
        .map(|p| p.ratio)
        .fold(None, |a: Option<f64>, r| Some(a.map_or(r, |a| a.max(r))));
    let describe = |p: Option<&PairedRatio>| p.map_or("not run".into(), |p| format!("{:.3}", p.ratio));
    out.push(Target::check(
        "a chain without view shapes / colliders pays nothing for them (ratio <= 1.03, the noise band)",
        format!(
            "100 x 16 without view shapes, orbiting / still camera: {}; colliders present but masked out / none: {} \
             (A/A control of the method: {})",
            describe(camera),
            describe(masked),
            describe(floor)
        ),
        worst.map(|w| w <= NOTHING),
    ));

    let abi: Vec<&PairedRatio> = report.paired.iter().filter(|p| p.what.starts_with("C ABI,")).collect();
    let abi_worst = abi.iter().map(|p| p.ratio).fold(None, |a: Option<f64>, r| Some(a.map_or(r, |a| a.max(r))));
    let mut measured =
        abi.iter().map(|p| format!("{}: {:+.1}%", p.what, (p.ratio - 1.0) * 100.0)).collect::<Vec<_>>().join("; ");
    if let Some(floor) = report.paired(FFI_NOISE_FLOOR) {
        let _ = write!(measured, " (A/A control of the method: {:+.1}%)", (floor.ratio - 1.0) * 100.0);
    }
    out.push(Target::check("C ABI overhead <= 5% at 100 chains", measured, abi_worst.map(|w| w <= 1.05)));

    // The issue asks for the scalar path: both sides on the scalar solver (a lone chain takes it anyway).
    let long = ns_per_joint(report, "1x1000", PLAIN_SCALAR.id);
    let many = ns_per_joint(report, "1000x16", PLAIN_SCALAR.id);
    let hair = ns_per_joint(report, LINEARITY_SCENE.name, PLAIN_SCALAR.id);
    let fallbacks = |scene: &str| {
        report
            .scene(scene, PLAIN_SCALAR.id)
            .and_then(|r| Some(r.counters.as_ref()?.solver_fallbacks / r.substeps.max(1) as f64))
    };
    // Interleaved frame-time ratio (long chain / 1000 x 16) times the joint ratio: per-joint cost ratio.
    let joints = |name: &str| find_scene(name).dynamic_joints() as f64;
    let per_joint = |what: &str, long: &str| report.paired(what).map(|p| p.ratio * joints("1000x16") / joints(long));
    let (rope, hair_paired) = (per_joint(LINEARITY_ROPE, "1x1000"), per_joint(LINEARITY_HAIR, LINEARITY_SCENE.name));
    let separate = long.zip(many).map(|(l, m)| l / m);
    out.push(Target::check(
        "per-joint cost of 1 x 1000 within 1.5x of 1000 x 16 (scalar solver)",
        match (rope, hair_paired) {
            (Some(r), Some(h)) => {
                format!(
                    "interleaved: ratio {r:.2} (the 0.8 m rope of 0.8 mm segments; the direct solve failed or was \
                 skipped on {} of its substeps, bug 1: the exact projection solves them), {h:.2} for the same \
                 1000 joints as 2.5 cm hair segments. From the separate medians above: {} and {} vs {} \
                 ns/joint/substep, ratios {} and {}",
                    fallbacks("1x1000").map_or("-".into(), |f| format!("{:.0}%", f * 100.0)),
                    perf_report::ns(long),
                    perf_report::ns(hair),
                    perf_report::ns(many),
                    separate.map_or("-".into(), |r| format!("{r:.2}")),
                    hair.zip(many).map_or("-".into(), |(h, m)| format!("{:.2}", h / m)),
                ) + if h > *LINEARITY_BAR.end() {
                    ". The verdict is the named 1 x 1000 scene's (the rope); the hair segments are above the bar"
                } else {
                    ""
                }
            }
            _ => "not run".into(),
        },
        rope.map(|r| LINEARITY_BAR.contains(&r)),
    ));

    out.push(solver_target(report));
    out.push(peer_target(report));
    out
}

/// The lane solver's speed-up over the scalar solver on 1000 x 16 (interleaved): for information, met when
/// the lane solver is faster at all.
fn solver_target(report: &Report) -> Target {
    let target = "lane solver speed-up over the scalar solver (interleaved, 1000 x 16)";
    let Some(big) = report.paired(LANES_1000) else {
        return Target::check(target, "not run".into(), None);
    };
    let speed_up = 1.0 / big.ratio;
    let mut measured = format!(
        "{speed_up:.2}x (scalar {} us, lanes {} us per frame, median over {} rounds)",
        micros(Some(big.a_seconds)),
        micros(Some(big.b_seconds)),
        big.rounds
    );
    if let Some(small) = report.paired(LANES_100) {
        let _ = write!(measured, "; 100 x 16: {:.2}x", 1.0 / small.ratio);
    }
    for (what, label) in [(LANES_1000_COLLIDERS, "1000 x 16"), (LANES_100_COLLIDERS, "100 x 16")] {
        if let Some(pair) = report.paired(what) {
            let _ = write!(measured, "; {label} with colliders: {:.2}x", 1.0 / pair.ratio);
        }
    }
    if let Some(floor) = report.paired(NOISE_FLOOR) {
        let _ = write!(measured, " (A/A control of the method: {:.3})", floor.ratio);
    }
    Target::check(target, measured, Some(speed_up > 1.0))
}

/// Faster than rapier3d at equal or lower pendulum error: every rapier pendulum row against kodawari's
/// (kodawari's physics error). The hair scene has no error measure: it is listed for information, against
/// both kodawari rows (default stiffness, and limp like rapier's chains), and does not decide the verdict.
fn peer_target(report: &Report) -> Target {
    let target = "faster than rapier3d at equal or lower pendulum error (pendulums decide; hair scene for information)";
    let kodawari: Vec<&PeerRow> = report.peers.iter().filter(|p| p.engine.starts_with("kodawari")).collect();
    let rapier: Vec<&PeerRow> = report.peers.iter().filter(|p| p.engine.starts_with("rapier")).collect();
    if rapier.is_empty() {
        return Target::check(target, "rapier3d not run (needs `--features peers`)".into(), None);
    }
    let mut verdict = None;
    let mut lines = Vec::new();
    for r in rapier {
        for k in kodawari.iter().filter(|k| k.scenario == r.scenario) {
            let (Some(tk), Some(tr)) = (k.frame_seconds, r.frame_seconds) else { continue };
            let speed = format!("{}, {} vs {}: {:.2}x the speed", r.scenario, k.engine, r.engine, tr / tk);
            // Both engines' poses after a call show the call's time (kodawari's has no display latency).
            match (k.error, r.error) {
                (Some(ek), Some(er)) => {
                    verdict = Some(verdict.unwrap_or(true) && tk < tr && ek <= er);
                    lines.push(format!("{speed}, error {ek:.1e} vs {er:.1e}"));
                }
                _ => lines.push(speed),
            }
        }
    }
    Target::check(target, lines.join("; "), verdict)
}

fn main() {
    let started = Instant::now();
    let benchmarking = is_benchmark_run();
    // Probe first: the bandwidth measurement wants a quiet process.
    let machine = benchmarking.then(Machine::probe);
    let mut criterion = Criterion::default().nresamples(10_000).configure_from_args();
    let recorder = Recorder::default();
    let mut report = Report::default();

    bench_scenes(&mut criterion, &recorder, &mut report);
    bench_ffi(&mut criterion, &recorder, &mut report);
    bench_pendulums(&mut criterion, &recorder, &mut report);
    bench_peer_scene(&mut criterion, &recorder, &mut report);
    if benchmarking {
        println!("interleaved ratios ...");
        interleaved_skips(&mut report);
        ffi_ratios(&mut report);
        if let Some(machine) = &machine {
            report.bound_ratio = Some(bound_ratio(machine));
        }
        for p in &report.paired {
            println!("{}: {} / {} = {:.3}", p.what, p.b, p.a, p.ratio);
        }
    }
    criterion.final_summary();

    let Some(machine) = machine else { return };
    let substeps = report.scene("1000x16", PLAIN.id).map_or(4.0, |r| r.substeps.max(1) as f64);
    let bound = Bound::new(&machine, substeps);
    report.targets = targets(&report, &bound);
    report.notes.push(format!(
        "The machine is shared (load average at the start {}, at the end {}): criterion medians of scenes measured \
         one after the other can differ by several percent, at times tens of percent, through other processes alone. \
         The interleaved ratios (and their A/A control) are the robust comparisons.",
        machine.load_average.as_deref().unwrap_or("unknown"),
        std::fs::read_to_string("/proc/loadavg").map_or("unknown".into(), |s| s.trim().to_owned())
    ));
    let markdown = report.markdown(&machine, &solver_path(), &bound, started.elapsed());
    let complete = !report.scenes.iter().any(|r| r.missing.as_deref() == Some(FILTERED_OUT));
    let path = if complete { Path::new("docs/performance.md") } else { Path::new("target/performance-partial.md") };
    std::fs::write(path, &markdown).expect("write the performance report");
    println!("\n{markdown}\nwrote {} in {:.0} s", path.display(), started.elapsed().as_secs_f64());
}
