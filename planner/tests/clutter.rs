//! Cluttered tables: a scene may hold up to `bounds::MAX_OBJECTS` (256)
//! objects and still validates and plans; one past it is refused naming the
//! field; an instruction moving more than `bounds::MAX_SUBGOALS` is not
//! executable. The `#[ignore]`d measurement prints plan time and peak heap
//! against 8, 32, 128 and 256 objects (`cargo test --release -p
//! afford-planner --test clutter -- --ignored --nocapture`): a counting
//! global allocator records the peak of live heap bytes, so the tests of
//! this binary run one at a time.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use afford_planner::scenario::{self, Format, Scenario, bounds};
use afford_planner::{PlanError, PlanOptions, plan};

struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// The counters are process-wide: one test at a time.
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

/// Pitch of the clutter's rows and columns, pixels.
const PITCH: usize = 16;
/// Clutter piece side, pixels (7.5 mm at 0.625 mm/px).
const PIECE: usize = 12;
/// Columns of clutter: u from 340 to 628 px, right of the target's route.
const COLUMNS: usize = 18;

/// The default scene's calibration and left box with the blue square to
/// move and `objects - 1` small pieces packed in rows of 18 on the back
/// right of the table, 16 px apart (up to 15 rows: v ≤ 246 px), away from
/// the target's route to the box.
fn cluttered_yaml(objects: usize, instruction: &str) -> String {
    let mut text = String::from(
        "afford: 1\nname: cluttered\ncamera:\n  width: 640\n  height: 480\n  \
         pixel_to_base: [[0.0, -0.000625, 0.66], [-0.000625, 0.0, 0.20]]\n  table_z: -0.40\n\
         robot: {model: kuka_iiwa14, start: [320, 460]}\nobjects:\n  \
         - {name: blue-square-1, color: blue, shape: square, box: [100, 80, 40, 40], height: 0.03}\n",
    );
    for k in 0..objects.saturating_sub(1) {
        let (row, column) = (k / COLUMNS, k % COLUMNS);
        let (u, v) = (340 + PITCH * column, 10 + PITCH * row);
        let colour = ["red", "green", "yellow"][k % 3];
        text.push_str(&format!(
            "  - {{name: piece-{k}, color: {colour}, shape: circle, box: [{u}, {v}, {PIECE}, {PIECE}], height: 0.02}}\n"
        ));
    }
    text.push_str("goals:\n  - {name: left box, box: [20, 300, 120, 120], height: 0.10}\n");
    text.push_str(&format!("instruction: \"{instruction}\"\n"));
    text
}

fn cluttered(objects: usize) -> Result<Scenario, afford_planner::ScenarioError> {
    let text = cluttered_yaml(objects, "put the blue square in the left box");
    scenario::parse(&text, Format::Yaml, "cluttered.yaml")
}

#[test]
fn a_table_of_256_objects_validates_and_plans() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    assert_eq!(bounds::MAX_OBJECTS, 256);
    let s = cluttered(256).expect("256 objects are accepted");
    assert_eq!(s.objects.len(), 256);
    let planned = plan(&s, &PlanOptions::default()).expect("plans");
    assert!(planned.unsolved.is_empty(), "{:?}", planned.unsolved);
    assert_eq!(planned.subgoals.len(), 1);
    assert_eq!(planned.subgoals[0].object, "blue-square-1");
    let trajectory = planned.subgoals[0].trajectory.as_ref().expect("timed");
    assert!(trajectory.points.len() > 2);
}

#[test]
fn a_table_of_257_objects_is_refused_naming_the_bound() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let message = cluttered(257).expect_err("refused").to_string();
    assert!(
        message.contains("objects: lists 257 entries; at most 256"),
        "{message}"
    );
}

#[test]
fn an_instruction_moving_more_than_32_objects_is_not_executable() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    let text = cluttered_yaml(40, "put all the circles in the left box");
    let s = scenario::parse(&text, Format::Yaml, "cluttered.yaml").expect("a valid scene");
    match plan(&s, &PlanOptions::default()) {
        Err(PlanError::Instruction(e)) => {
            let message = e.to_string();
            assert!(
                message.contains("asks for 39 moves") && message.contains("at most 32"),
                "{message}"
            );
        }
        other => panic!("expected an instruction error, got {other:?}"),
    }
}

/// Plan time and peak heap of the whole pipeline against the object count.
#[test]
#[ignore = "measurement: prints a table, run with --ignored --nocapture"]
fn clutter_plan_time_and_peak_memory() {
    let _serial = SERIAL.lock().unwrap_or_else(|e| e.into_inner());
    eprintln!("| objects | validate ms | plan ms | peak heap MB |");
    eprintln!("|---|---|---|---|");
    for n in [8, 32, 128, 256] {
        let text = cluttered_yaml(n, "put the blue square in the left box");
        let started = Instant::now();
        let s = scenario::parse(&text, Format::Yaml, "cluttered.yaml").expect("valid");
        let validate_ms = started.elapsed().as_secs_f64() * 1e3;
        let started = Instant::now();
        let (planned, peak) = peak_of(|| plan(&s, &PlanOptions::default()));
        let plan_ms = started.elapsed().as_secs_f64() * 1e3;
        let planned = planned.expect("plans");
        assert_eq!(planned.subgoals.len(), 1, "{n} objects");
        eprintln!(
            "| {n} | {validate_ms:.1} | {plan_ms:.0} | {:.1} |",
            peak as f64 / 1e6
        );
        assert!(peak < bounds::MEMORY_BOUND_BYTES);
    }
}
