//! The allowed-collision matrix: the matrices stored with the built-in robots
//! are what `afford robots acm` derives, every pair they call `never` stays
//! clear in a fresh sample, and the self-collision check skips exactly the
//! stored pairs (adjacent ones included) and checks every other pair.

use std::collections::BTreeSet;

use afford_collision::{AcmSettings, AllowedCollisionMatrix, CollisionError, RobotGeometry};
use afford_kinematics::{AllowedReason, RobotModel};

fn stored_settings(m: &RobotModel) -> AcmSettings {
    let a = m
        .allowed_collisions()
        .expect("built-in robots store their matrix");
    AcmSettings {
        samples: a.samples,
        seed: a.seed,
        clearance: a.clearance,
        ..AcmSettings::default()
    }
}

#[test]
fn stored_matrices_are_what_the_command_derives() {
    for name in ["kuka_iiwa14", "care_o_bot4"] {
        let m = RobotModel::builtin(name).unwrap();
        let settings = stored_settings(&m);
        assert!(settings.samples >= 10_000, "{name}: {settings:?}");
        let derived = AllowedCollisionMatrix::derive(&m, &settings).unwrap();
        assert_eq!(
            Some(&derived.to_section()),
            m.allowed_collisions(),
            "{name}: robots/{name}.yaml is stale: regenerate it with `afford robots acm {name}`"
        );
    }
}

#[test]
fn never_pairs_stay_clear_in_a_fresh_sample() {
    for name in ["kuka_iiwa14", "care_o_bot4"] {
        let m = RobotModel::builtin(name).unwrap();
        let fresh = AcmSettings {
            samples: 20_000,
            seed: 20_260_101,
            ..stored_settings(&m)
        };
        let sample = AllowedCollisionMatrix::derive(&m, &fresh).unwrap();
        let stored = m.allowed_collisions().unwrap();
        let mut never = 0;
        for p in stored
            .pairs
            .iter()
            .filter(|p| p.reason == AllowedReason::Never)
        {
            never += 1;
            let seen = sample.pairs.iter().find(|s| s.links == p.pair).unwrap();
            assert!(
                seen.min_distance > Some(0.5 * stored.clearance),
                "{name}: never pair {:?} came within {:?} m",
                p.pair,
                seen.min_distance
            );
        }
        assert!(never > 0, "{name}: no never pairs to test");
    }
}

#[test]
fn self_collision_check_skips_exactly_the_stored_pairs() {
    for name in ["kuka_iiwa14", "care_o_bot4"] {
        let m = RobotModel::builtin(name).unwrap();
        let g = RobotGeometry::new(&m).unwrap();
        let link = |body: &str| body.split('#').next().unwrap().to_string();
        let checked: BTreeSet<[String; 2]> = g
            .self_collision_pairs()
            .iter()
            .map(|(a, b)| [link(a), link(b)])
            .collect();
        let derived = AllowedCollisionMatrix::derive(&m, &stored_settings(&m)).unwrap();
        for p in &derived.pairs {
            assert_eq!(
                checked.contains(&p.links),
                p.reason.is_none(),
                "{name}: {:?} ({:?})",
                p.links,
                p.reason
            );
        }
        // No checked pair falls outside the matrix.
        assert!(
            checked
                .iter()
                .all(|c| derived.pairs.iter().any(|p| &p.links == c))
        );
        let counts: Vec<usize> = [
            Some(AllowedReason::Adjacent),
            Some(AllowedReason::Default),
            Some(AllowedReason::Always),
            Some(AllowedReason::Never),
            None,
        ]
        .iter()
        .map(|r| derived.count(*r))
        .collect();
        println!("{name}: adjacent, default, always, never, checked = {counts:?}");
    }
}

#[test]
fn acm_is_deterministic_and_seeded() {
    let m = RobotModel::builtin("kuka_iiwa14").unwrap();
    let s = AcmSettings {
        samples: 3_000,
        ..AcmSettings::default()
    };
    let a = AllowedCollisionMatrix::derive(&m, &s).unwrap();
    assert_eq!(a, AllowedCollisionMatrix::derive(&m, &s).unwrap());
    assert_eq!(
        a.to_yaml(),
        AllowedCollisionMatrix::derive(&m, &s).unwrap().to_yaml()
    );
    let other = AllowedCollisionMatrix::derive(&m, &AcmSettings { seed: 2, ..s }).unwrap();
    let distances = |x: &AllowedCollisionMatrix| -> Vec<u64> {
        x.pairs
            .iter()
            .filter_map(|p| p.min_distance.map(f64::to_bits))
            .collect()
    };
    assert_ne!(
        distances(&a),
        distances(&other),
        "the seed changes the samples"
    );
}

#[test]
fn acm_settings_out_of_range_name_the_field() {
    let m = RobotModel::builtin("kuka_iiwa14").unwrap();
    for (settings, field) in [
        (
            AcmSettings {
                samples: 0,
                ..AcmSettings::default()
            },
            "samples",
        ),
        (
            AcmSettings {
                samples: u64::MAX,
                ..AcmSettings::default()
            },
            "samples",
        ),
        (
            AcmSettings {
                clearance: f64::NAN,
                ..AcmSettings::default()
            },
            "clearance",
        ),
        (
            AcmSettings {
                clearance: -0.01,
                ..AcmSettings::default()
            },
            "clearance",
        ),
        (
            AcmSettings {
                always_fraction: 0.2,
                ..AcmSettings::default()
            },
            "always_fraction",
        ),
    ] {
        let e = AllowedCollisionMatrix::derive(&m, &settings).unwrap_err();
        assert!(
            matches!(&e, CollisionError::Settings { field: f, .. } if f == field),
            "{e}"
        );
    }
}

#[test]
fn user_robot_matrix_loads_back_into_its_description() {
    // A user's robot: derive, paste the block into its description, load it.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../kinematics/tests/fixtures");
    let m = RobotModel::load("six_dof.yaml", &dir).unwrap();
    let acm = AllowedCollisionMatrix::derive(
        &m,
        &AcmSettings {
            samples: 2_000,
            ..AcmSettings::default()
        },
    )
    .unwrap();
    let text = std::fs::read_to_string(dir.join("six_dof.yaml")).unwrap() + &acm.to_yaml();
    let urdf = std::fs::read_to_string(dir.join("six_dof.urdf")).unwrap();
    let with = RobotModel::from_texts(
        &text,
        std::path::Path::new("six_dof.yaml"),
        &urdf,
        std::path::Path::new("six_dof.urdf"),
    )
    .unwrap();
    assert_eq!(with.allowed_collisions(), Some(&acm.to_section()));
    let skipped = acm.pairs.iter().filter(|p| p.reason.is_some()).count();
    assert_eq!(with.self_collision_skip().len(), skipped);
    assert!(
        skipped > m.self_collision_skip().len(),
        "sampling adds pairs"
    );
}

#[test]
fn a_mimic_finger_is_sampled_through_its_leader() {
    // The right finger mirrors the left: the two meet only as the left
    // closes, and the knuckle (a mimic of the right finger) stays adjacent
    // to the finger it turns on.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../kinematics/tests/fixtures");
    let m = RobotModel::load("mimic_gripper.yaml", &dir).unwrap();
    let settings = AcmSettings {
        samples: 2_000,
        ..AcmSettings::default()
    };
    let acm = AllowedCollisionMatrix::derive(&m, &settings).unwrap();
    let entry = |a: &str, b: &str| {
        acm.pairs
            .iter()
            .find(|p| p.links == [a, b])
            .unwrap_or_else(|| panic!("no pair {a} {b}"))
    };
    let fingers = entry("finger_left", "finger_right");
    assert_eq!(fingers.reason, None, "{fingers:?}");
    let (closest, touching) = (
        fingers.min_distance.unwrap(),
        fingers.contact_fraction.unwrap(),
    );
    assert!(closest < 0.002 && touching < 0.05, "{fingers:?}");
    assert_eq!(
        entry("finger_right", "knuckle").reason,
        Some(afford_kinematics::AllowedReason::Adjacent)
    );
}
