//! The robot description + URDF loader: no input may panic. The input is a
//! description YAML and a URDF separated by a NUL byte.
#![no_main]

use std::path::Path;

use afford_kinematics::RobotModel;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (description, urdf) = text.split_once('\0').unwrap_or((text, ""));
    let Ok(model) = RobotModel::from_texts(
        description,
        Path::new("fuzz.yaml"),
        urdf,
        Path::new("fuzz.urdf"),
    ) else {
        return;
    };
    // Accepted: forward kinematics of home is finite.
    for arm in model.arms() {
        let pose = arm.fk(&arm.home);
        assert!(pose.translation.vector.iter().all(|x| x.is_finite()));
    }
});
