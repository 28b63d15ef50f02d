//! The size bounds of a robot description and its URDF, in one place. The
//! loader checks every one before it builds anything, naming the element at
//! fault, so a user robot cannot ask for unbounded work or feed absurd
//! numbers to forward kinematics, IK or the collision library (parry's
//! penetration solver panics on shapes of 1e308 m). README.md ("Limits")
//! lists them.

/// Largest description `.yaml` or URDF read, bytes (4 MiB; the built-in
/// Care-O-bot's URDF is under 100 kB).
pub const MAX_FILE_BYTES: u64 = 4 << 20;

/// Most links in a URDF (the Care-O-bot 4 has about 60).
pub const MAX_LINKS: usize = 512;

/// Most joints in a URDF (fixed ones included).
pub const MAX_JOINTS: usize = 512;

/// Most movable joints of a robot (the collision check tracks up to 128).
pub const MAX_MOVABLE_JOINTS: usize = 128;

/// Most `<collision>` elements of one link.
pub const MAX_COLLIDERS_PER_LINK: usize = 64;

/// Largest size of a collision shape (box side, cylinder or capsule length,
/// radius), metres (10 m: no robot part is larger).
pub const MAX_SHAPE_SIZE_M: f64 = 10.0;

/// Smallest size of a collision shape, metres (0.1 mm).
pub const MIN_SHAPE_SIZE_M: f64 = 1e-4;

/// Largest collision mesh file read, bytes (64 MiB: a binary STL of 1.3
/// million triangles).
pub const MAX_MESH_FILE_BYTES: u64 = 64 << 20;

/// Most vertices of a collision mesh's convex hull (a hull with more needs
/// a simplified mesh: every distance query visits its vertices).
pub const MAX_HULL_VERTICES: usize = 4096;

/// Largest `<mimic multiplier>` magnitude.
pub const MAX_MIMIC_MULTIPLIER: f64 = 100.0;

/// Largest offset of a joint or collision `<origin xyz>`, metres per axis.
pub const MAX_OFFSET_M: f64 = 10.0;

/// Largest angle of an `<origin rpy>`, rad.
pub const MAX_ORIGIN_ANGLE_RAD: f64 = 4.0 * std::f64::consts::PI;

/// Largest magnitude of a revolute joint's limits, and of any rotational
/// joint value in `home` or `park` (continuous joints included), rad (two
/// turns each way).
pub const MAX_REVOLUTE_LIMIT_RAD: f64 = 4.0 * std::f64::consts::PI;

/// Largest magnitude of a prismatic joint's limits or value, metres.
pub const MAX_PRISMATIC_LIMIT_M: f64 = 10.0;

/// Joint velocity limits, rad/s or m/s: at least 1 mrad/s (a slower joint
/// makes a sub-goal last hours), at most 100.
pub const VELOCITY_LIMIT_RANGE: (f64, f64) = (1e-3, 100.0);

/// Joint acceleration limits, rad/s² or m/s²: at least 1e-3, at most 10,000.
pub const ACCELERATION_LIMIT_RANGE: (f64, f64) = (1e-3, 1e4);

/// Joint jerk limits, rad/s³ or m/s³: at least 1e-2, at most 10⁶.
pub const JERK_LIMIT_RANGE: (f64, f64) = (1e-2, 1e6);

/// Largest gripper opening or finger length, metres.
pub const MAX_GRIPPER_SIZE_M: f64 = 1.0;

/// `Err` with the problem when the text is longer than [`MAX_FILE_BYTES`].
pub(crate) fn check_file_size(len: u64) -> Result<(), String> {
    if len > MAX_FILE_BYTES {
        return Err(format!(
            "the file is larger than {MAX_FILE_BYTES} bytes, the largest robot file read"
        ));
    }
    Ok(())
}

/// `Err` with the problem when `value` is not finite or outside `lo..=hi`.
pub(crate) fn check_range(what: &str, value: f64, (lo, hi): (f64, f64)) -> Result<(), String> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        return Ok(());
    }
    Err(format!(
        "{what} must be between {lo} and {hi}, got {value:?}"
    ))
}
