//! Runs one of the performance report's scenes (`benches/support/scenes.rs`) for a fixed number of frames,
//! for instruction counts that do not depend on the machine's load, e.g. the linearity figures of
//! `docs/robustness.md` (bug 1):
//! `valgrind --tool=callgrind target/release/examples/scene_cost 60 1x1000_hair scalar`, then divide the total
//! by the dynamic joints and substeps printed. Scenes: `100x16`, `1000x16`, `1x1000` (0.8 m rope),
//! `1x1000_hair` (2.5 cm segments), `ragged` (the report's 200 chains of 4 to 32 joints); variants: `lanes`
//! (default), `scalar`, `colliders` (the head sphere, shoulders and ground of the report's colliders variant, on
//! the lane solver) and `colliders_scalar`, `asleep` and `awake_at_rest` (the sleeping-chain skip's pair), `lod1`
//! and `lod2`, `views` (three view shapes per chain, orbiting camera), `limp` (stiffness 0). It also prints the
//! engine's state hash and the contact pairs tested, so that two builds can be checked to compute the same
//! bits on a scene, and last the mean time of a frame, for `tools/ab.sh` (interleaved timing of two builds:
//! `tools/ab.sh OLD NEW 20 200 100x16 views`).

#[path = "../benches/support/scenes.rs"]
mod scenes;

use scenes::{
    ASLEEP, AWAKE_AT_REST, COLLIDERS, COLLIDERS_SCALAR, LIMP, LOD1, LOD2, PLAIN, PLAIN_SCALAR, ReadBack, Scene,
    SceneRun, VIEWS, VIEWS_COLLIDERS,
};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: scene_cost FRAMES 1x8|100x16|1000x16|16384x16|1x256|1x1000|1x1000_hair|ragged [lanes|scalar|colliders|colliders_scalar|asleep|awake_at_rest|lod1|lod2|views|views_colliders|limp]";
    let frames: u64 = args.first().and_then(|f| f.parse().ok()).expect(usage);
    let scene = match args.get(1).map(String::as_str) {
        Some("1x8") => Scene::uniform("1x8", 1, 8),
        Some("100x16") => Scene::uniform("100x16", 100, 16),
        Some("1000x16") => Scene::uniform("1000x16", 1000, 16),
        Some("16384x16") => Scene::uniform("16384x16", 16384, 16),
        Some("1x256") => Scene::uniform("1x256", 1, 256),
        Some("1x1000") => Scene::uniform("1x1000", 1, 1000),
        Some("1x1000_hair") => Scene::uniform("1x1000_hair", 1, 1000).with_segment(0.025),
        Some("ragged") => Scene::ragged("ragged", 200, 4, 32),
        _ => panic!("{usage}"),
    };
    let variant = match args.get(2).map(String::as_str) {
        Some("scalar") => PLAIN_SCALAR,
        Some("colliders") => COLLIDERS,
        Some("colliders_scalar") => COLLIDERS_SCALAR,
        Some("asleep") => ASLEEP,
        Some("awake_at_rest") => AWAKE_AT_REST,
        Some("lod1") => LOD1,
        Some("lod2") => LOD2,
        Some("views") => VIEWS,
        Some("views_colliders") => VIEWS_COLLIDERS,
        Some("limp") => LIMP,
        _ => PLAIN,
    };
    let mut run = SceneRun::new(&scene, variant, ReadBack::World).expect("the scene builds");
    // `asleep`: the frames until every chain sleeps come first (subtract a run of 0 frames).
    if let Some(note) = run.settle() {
        println!("{note}");
    }
    let start = std::time::Instant::now();
    for _ in 0..frames {
        run.frame();
    }
    let frame_time = start.elapsed().as_nanos() as f64 / frames.max(1) as f64;
    let stats = run.engine.stats();
    println!("hash {:016x} pairs {}", run.engine.state_hash(), stats.contact_pairs_tested);
    println!(
        "{} ({}), {}: {} dynamic joints, {} substeps, {} solver fallbacks",
        scene.name,
        scene.shape_label(),
        variant.label,
        scene.dynamic_joints(),
        stats.substeps_total,
        stats.solver_fallbacks
    );
    // Last, in the form `tools/ab.sh` reads, for interleaved timing of two builds.
    println!("frame {frame_time:.0} ns");
}
