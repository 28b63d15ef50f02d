//! The documented memory bound (README "Limits", `scenario::bounds`),
//! measured: a counting global allocator records the peak of live heap bytes
//! while the largest accepted grid is built and learnt on with the largest
//! learner budget, and the trajectory guard refuses what would exceed its
//! share. One test binary of its own, one test at a time (the allocator
//! counts the whole process).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use afford_planner::grid::GridRequest;
use afford_planner::scenario::{self, Format, bounds};
use afford_planner::timing::{
    JointLimits, MAX_SAMPLES, TimingError, TimingSettings, time_parameterize,
};
use afford_planner::{PlanOptions, Stage, StateGrid, plan};

struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// Tests of this binary run one at a time: the counters are process-wide.
static SERIAL: Mutex<()> = Mutex::new(());

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, p: *mut u8, layout: Layout) {
        unsafe { System.dealloc(p, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Peak live heap bytes above the level before `f` ran.
fn peak_of<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let before = LIVE.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    let value = f();
    (value, PEAK.load(Ordering::Relaxed) - before)
}

/// The largest grid validation accepts: an 8000 × 8000 image at 1 mm/px
/// (corners 4 m from the base) and a 40 × 40 px target, 200 × 200 cells.
fn largest_grid_scenario() -> scenario::Scenario {
    let text = r#"
afford: 1
camera:
  width: 8000
  height: 8000
  pixel_to_base: [[0.0, -0.001, 4.0], [-0.001, 0.0, 4.0]]
  table_z: -0.2
robot: {model: kuka_iiwa14, start: [20, 20]}
objects:
  - {name: piece, color: blue, shape: square, box: [7900, 7900, 40, 40], height: 0.03}
goals:
  - {name: box, box: [0, 7800, 200, 200], height: 0.1}
instruction: "put the blue square in the box"
learner: {max_steps: 1000000, convergence_window: 1000000}
"#;
    scenario::parse(text, Format::Yaml, "largest.yaml").expect("the largest grid is accepted")
}

#[test]
fn largest_accepted_grid_plans_within_the_grid_and_learner_bound() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let s = largest_grid_scenario();
    let cells = bounds::grid_cells_bound(s.camera.width, s.camera.height, 40.0, 40.0);
    assert_eq!(cells, bounds::MAX_GRID_CELLS as f64);
    let options = PlanOptions {
        until: Stage::Grid,
        ..PlanOptions::default()
    };
    let request = GridRequest {
        object: 0,
        goal: 0,
        gripper: s.robot.start.expect("the scene gives robot.start"),
    };
    assert_eq!(StateGrid::build(&s, request).len(), bounds::MAX_GRID_CELLS);
    // Solved or not, the learner spends its whole budget on this grid.
    let (planned, peak) = peak_of(|| plan(&s, &options));
    let steps = match planned {
        Ok(p) => p.subgoals[0].training_steps,
        Err(e) => {
            assert!(e.to_string().contains("1000000 training steps"), "{e}");
            bounds::MAX_LEARNER_STEPS
        }
    };
    assert!(steps > 0);
    let bound = bounds::MAX_GRID_CELLS * bounds::BYTES_PER_CELL + bounds::MAX_LEARNER_STEPS * 40;
    eprintln!("largest grid: peak {peak} bytes, bound {bound} bytes");
    assert!(peak <= bound, "peak {peak} bytes above the bound {bound}");
}

#[test]
fn timing_refuses_a_piece_longer_than_max_samples_before_sampling() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    // 1 rad at 1 mrad/s: about 1000 s, 100,000 samples at 100 Hz.
    let path = vec![vec![0.0], vec![0.5], vec![1.0]];
    let limits = JointLimits {
        lower: vec![-10.0],
        upper: vec![10.0],
        velocity: vec![1e-3],
        acceleration: vec![1.0],
        jerk: Vec::new(),
    };
    let (result, peak) =
        peak_of(|| time_parameterize(&path, &limits, None, &TimingSettings::default()));
    match result {
        Err(TimingError::TooManySamples { samples, .. }) => {
            assert!(samples > MAX_SAMPLES as f64, "{samples}")
        }
        other => panic!("expected TooManySamples, got {other:?}"),
    }
    // Nothing near 100,000 samples was allocated (one sample is > 80 bytes).
    assert!(peak < 100_000 * 80, "peak {peak} bytes");
}

#[test]
fn a_piece_at_the_sample_bound_stays_within_its_share_of_the_memory_bound() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    // 16 joints (the most an arm may have), timed at the top rate until
    // just under the sample bound.
    let joints = 16;
    let path: Vec<Vec<f64>> = (0..3).map(|k| vec![0.45 * k as f64; joints]).collect();
    let limits = JointLimits {
        lower: vec![-10.0; joints],
        upper: vec![10.0; joints],
        velocity: vec![0.1; joints],
        acceleration: vec![1.0; joints],
        jerk: Vec::new(),
    };
    let settings = TimingSettings {
        rate_hz: bounds::MAX_RATE_HZ,
        ..TimingSettings::default()
    };
    // The trajectory and its pretty JSON (what `afford plan` prints) together.
    let ((trajectory, json), peak) = peak_of(|| {
        let timed = time_parameterize(&path, &limits, None, &settings).unwrap();
        let trajectory = timed.trajectory.expect("timed");
        let json = serde_json::to_string_pretty(&trajectory).unwrap();
        (trajectory, json)
    });
    let samples = trajectory.points.len();
    assert!(json.len() > samples * 100, "{} bytes of JSON", json.len());
    assert!(
        samples <= MAX_SAMPLES && samples > MAX_SAMPLES / 2,
        "{samples}"
    );
    let share = MAX_SAMPLES * bounds::BYTES_PER_SAMPLE;
    eprintln!("{samples} samples of 16 joints: peak {peak} bytes, share {share} bytes");
    assert!(peak <= share, "peak {peak} bytes above {share}");
}
