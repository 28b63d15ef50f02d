//! The size bounds of a scenario, in one place. Every size-like input has a
//! documented limit that validation checks before any work starts (exit 2,
//! field named), so no accepted input can ask for unbounded memory or time.
//! README.md ("Limits") lists them with the memory bound they imply; the
//! derivation is in [`MEMORY_BOUND_BYTES`].

/// Largest scenario file read, bytes (1 MiB). A scenario is a few kB; the
/// bound keeps the parser's memory linear in something small.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// Largest image side, pixels (8192: an 8K camera).
pub const MAX_IMAGE_SIDE_PX: u32 = 8192;

/// Most grid cells a target may cut the image into (rows × columns). The
/// paper's grids reach 40 × 40; 40,000 (e.g. 200 × 200) leaves room for
/// small pieces on a wide table while every per-cell table stays small.
pub const MAX_GRID_CELLS: usize = 40_000;

/// Smallest side of a box, pixels (all boxes: objects, goals, hands).
pub const MIN_BOX_SIDE_PX: f64 = 1.0;

/// Smallest side of an object on the table, metres (5 mm): the gripper
/// cannot pick anything smaller, and with [`MAX_GRID_CELLS`] it keeps the
/// grid of a tiny calibration bounded.
pub const MIN_OBJECT_SIDE_M: f64 = 0.005;

/// Every image corner maps to a table point within this distance of the
/// robot base along x and y, and `|table_z|` stays below it, metres (10 m).
/// Bounds every tool path's length and so the number of waypoints.
pub const MAX_TABLE_EXTENT_M: f64 = 10.0;

/// Largest skew of `camera.pixel_to_base`, degrees: the image's u and v axes
/// must map to table directions perpendicular within this. Every box is
/// modelled as a rectangle (planner, collision scene and the independent
/// check alike); a skewed map turns it into a parallelogram whose corners
/// reach outside the model (a 10 cm hand at 1° skew: 1.7 mm, well inside
/// any margin; at 45°: 7 cm).
pub const MAX_CALIBRATION_SKEW_DEG: f64 = 1.0;

/// Largest |`robot.joints.<name>`|, rad or m. Joint limits bound every
/// other joint tighter; a continuous joint takes any value within it. The
/// independent check reads no position beyond it
/// (`afford_check::format::MAX_ABS_POSITION`); at 1e17 rad the transit's
/// continuous check never ended, at 1e300 IK got a non-finite target.
pub const MAX_JOINT_POSITION: f64 = 1e3;

/// Smallest height of an object, goal wall or hand, metres (5 mm). Above the
/// 2 mm slice of a held object that may rest on its support
/// ([`crate::clearance::SUPPORT_GAP`]), so a held object always has a body.
pub const MIN_HEIGHT_M: f64 = 0.005;

/// Largest height of an object, goal wall or hand, metres (2 m): taller than
/// any arm's reach, so a larger value is a typo, never a scene.
pub const MAX_HEIGHT_M: f64 = 2.0;

/// Most objects on the table (a cluttered table: pieces in a tray, a
/// heap of parts). Every per-object cost is linear in it: the grid paints
/// each object's cells once, the collision scene holds one box per object
/// (a few kB each), the affordance masks and the Q-table are per grid cell,
/// not per object. `planner/tests/clutter.rs` measures plan time and peak
/// memory for 8 to 256 objects.
pub const MAX_OBJECTS: usize = 256;

/// Most sub-goals one instruction can ask for: each object moves at most
/// once per instruction, and each sub-goal's trajectory has its share of
/// [`MEMORY_BOUND_BYTES`]. An instruction that names more ("put every piece
/// in the tray" on a table of 100) is not executable as one (exit 1, "name
/// fewer objects"); the scene itself may hold [`MAX_OBJECTS`].
pub const MAX_SUBGOALS: usize = 32;

/// Most goals (boxes).
pub const MAX_GOALS: usize = 16;

/// Most hands.
pub const MAX_HANDS: usize = 16;

/// Most `observations` entries (a scripted execution: a few changes per
/// sub-goal for the most sub-goals would be far fewer).
pub const MAX_OBSERVATIONS: usize = 64;

/// Latest `observations[i].at`, seconds of execution (one hour).
pub const MAX_EXECUTION_TIME_S: f64 = 3_600.0;

/// Most `sensitive` entries.
pub const MAX_SENSITIVE: usize = 64;

/// Longest name, colour, shape, `sensitive` entry or robot model, characters.
pub const MAX_NAME_CHARS: usize = 200;

/// Longest instruction, characters (a spoken instruction is a sentence or two).
pub const MAX_INSTRUCTION_CHARS: usize = 2_000;

/// Most clauses in an instruction. Counted conservatively before parsing:
/// one more than the separators (`,` `;` `.` `!` `?` `:`, "and", "then").
pub const MAX_CLAUSES: usize = 64;

/// Largest learner budget `learner.max_steps` (and `episode_steps`,
/// `convergence_window`), environment steps.
pub const MAX_LEARNER_STEPS: usize = 1_000_000;

/// Lowest controller rate, Hz.
pub const MIN_RATE_HZ: f64 = 1.0;

/// Highest controller rate, Hz (1 kHz: the fastest common arm interfaces,
/// e.g. KUKA FRI, run at 1 kHz).
pub const MAX_RATE_HZ: f64 = 1_000.0;

/// Largest value of any `safety.separation` field in its unit (m, s, m/s,
/// m/s²). Physical values are below 10; the bound keeps the speed caps of
/// the timing stage well inside floating point.
pub const MAX_SEPARATION_VALUE: f64 = 100.0;

/// Smallest non-zero `safety.separation.min_tool_speed_m_s`, m/s (1 mm/s):
/// a slower crawl would make a sub-goal last hours.
pub const MIN_CRAWL_SPEED_M_S: f64 = 0.001;

/// The trajectory of one sub-goal holds at most this many samples: it is
/// timed in three pieces (to the grasp, carrying, retreating; see
/// [`crate::trajectory`]) and the timing stage refuses a piece of more than
/// [`crate::timing::MAX_SAMPLES`] samples (`duration × rate + 1`; 100 s at
/// 100 Hz, 10 s at 1 kHz) before it samples; the arm rests while the
/// gripper closes and opens, at most
/// [`afford_kinematics::MAX_GRIPPER_TIME`] each, sampled at the rate.
pub const MAX_SAMPLES_PER_SUBGOAL: usize = 3 * crate::timing::MAX_SAMPLES
    + 2 * ((afford_kinematics::MAX_GRIPPER_TIME * MAX_RATE_HZ) as usize + 2);

/// Bytes per grid cell of one sub-goal's largest tables: the Q-table
/// (2 states × 7 actions × 8 bytes = 112), the oracle's parents and flags
/// (2 × 24 + 2), the GOAL entry per cell (24), the affordance masks and
/// contextual values (2 × 5), the cell codes (1), with room for the
/// rendered grid of `afford validate` (1 byte per cell and line) — rounded
/// up to 256.
pub const BYTES_PER_CELL: usize = 256;

/// Bytes per sample of a trajectory, for the largest arm (16 joints): one
/// `TrajectoryPoint` (3 vectors of 16 × 8 bytes, their headers, the time,
/// about 500 bytes) and its pretty JSON (49 numbers of about 30 bytes, each
/// on its own line, with the string's growth by doubling), measured at
/// about 3 kB by `planner/tests/memory_bound.rs` — rounded up to 4 kB.
pub const BYTES_PER_SAMPLE: usize = 4_096;

/// Bytes per object of the scene, for the structures that hold one entry
/// per object while a sub-goal is planned: its collision box (a parry
/// cuboid and its pose, a few hundred bytes, in the planner's scene and in
/// the transit's), its row of the grid painting, its name in the lookups —
/// rounded up to 64 kB; `planner/tests/clutter.rs` measures the growth
/// from 8 to 256 objects (well under this per object).
pub const BYTES_PER_OBJECT: usize = 64 << 10;

/// The memory bound of any accepted scenario, bytes (about 4.8 GB):
///
/// ```text
/// grid and learner: MAX_GRID_CELLS × BYTES_PER_CELL                      10 MB
///   + one episode of the learner: MAX_LEARNER_STEPS × 40 B               40 MB
/// trajectories:     MAX_SUBGOALS × MAX_SAMPLES_PER_SUBGOAL × BYTES_PER_SAMPLE
///                                                   ≈ 4.4 GB (32 × 34,004 × 4 kB)
/// the scenario itself and its copy per sub-goal: MAX_FILE_BYTES × 32     34 MB
/// the scene's objects: MAX_OBJECTS × BYTES_PER_OBJECT                    17 MB
/// plus 256 MB for the robot, the collision scene and the timing program.
/// ```
///
/// Only a 16-joint arm at the top rate (1 kHz) moving 32 objects, each
/// sub-goal 30 s long, comes near it; the examples plan in under 100 MB.
pub const MEMORY_BOUND_BYTES: usize = MAX_GRID_CELLS * BYTES_PER_CELL
    + MAX_LEARNER_STEPS * 40
    + MAX_SUBGOALS * MAX_SAMPLES_PER_SUBGOAL * BYTES_PER_SAMPLE
    + (MAX_FILE_BYTES as usize) * MAX_SUBGOALS
    + MAX_OBJECTS * BYTES_PER_OBJECT
    + (256 << 20);

// A held object always keeps a body above its support slice, and the
// documented memory bound stays what README "Limits" says (under 4.5 GiB).
const _: () = assert!(MIN_HEIGHT_M > crate::clearance::SUPPORT_GAP);
const _: () = assert!(MEMORY_BOUND_BYTES < 9 << 29);

/// Checks a controller rate (Hz): finite, within
/// [`MIN_RATE_HZ`]..=[`MAX_RATE_HZ`]. `Err` says what is wrong.
pub fn check_rate(rate_hz: f64) -> Result<(), String> {
    if rate_hz.is_finite() && (MIN_RATE_HZ..=MAX_RATE_HZ).contains(&rate_hz) {
        Ok(())
    } else {
        Err(format!(
            "must be a rate between {MIN_RATE_HZ} and {MAX_RATE_HZ} Hz, got {rate_hz:?}"
        ))
    }
}

/// Grid rows and columns the largest a target of `w` × `l` pixels can cut a
/// `width` × `height` image into, wherever the target lies: the grid's
/// origin is within half a cell of pixel 0, so at most `ceil(side / cell)`
/// cells fit along each axis ([`crate::grid::StateGrid::build`]). Saturates
/// instead of overflowing.
pub fn grid_cells_bound(width: u32, height: u32, w: f64, l: f64) -> f64 {
    let along = |side: u32, cell: f64| (side as f64 / cell).ceil().max(1.0);
    along(width, w) * along(height, l)
}

/// Clauses an instruction can have at most: separators + 1 (see [`MAX_CLAUSES`]).
pub fn clause_count_bound(instruction: &str) -> usize {
    let punctuation = instruction
        .chars()
        .filter(|c| matches!(c, ',' | ';' | '.' | '!' | '?' | ':'))
        .count();
    let words = instruction
        .split(|c: char| !c.is_alphanumeric())
        .filter(|w| w.eq_ignore_ascii_case("and") || w.eq_ignore_ascii_case("then"))
        .count();
    punctuation + words + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_bound_covers_the_built_grid_wherever_the_target_lies() {
        use crate::grid::{GridRequest, StateGrid};
        let mut s = crate::scenario::default_scenario().unwrap();
        for (u, v) in [(0.0, 0.0), (13.7, 455.1), (600.0, 3.3), (299.5, 200.25)] {
            s.objects[0].bbox = crate::scenario::PixelBox {
                u,
                v,
                w: 17.3,
                l: 23.9,
            };
            let grid = StateGrid::build(
                &s,
                GridRequest {
                    object: 0,
                    goal: 0,
                    gripper: [1.0, 1.0],
                },
            );
            let bound = grid_cells_bound(s.camera.width, s.camera.height, 17.3, 23.9);
            assert!((grid.len() as f64) <= bound, "{} > {bound}", grid.len());
        }
    }

    #[test]
    fn clause_count_bound_counts_separators() {
        assert_eq!(clause_count_bound("put the red one in the box"), 1);
        assert_eq!(clause_count_bound("put a, b and c then d; e."), 6);
    }
}
