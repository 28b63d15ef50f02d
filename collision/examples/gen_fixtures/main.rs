//! Generates the regression fixtures in `tests/collision/` by computing them:
//! configurations by FK, obstacles placed relative to computed link
//! positions, margins of the grazing fixtures from the exact closest approach
//! (dense sampling at 10 µm / 2e-5 rad) ± 1 mm, and every verdict from the
//! dense reference (0.5 mm / 0.001 rad). A fixture is only written when the
//! fast check agrees with the dense reference.
//!
//! `cargo run --release -p afford-collision --example gen_fixtures`

use std::path::PathBuf;

use afford_collision::*;
use afford_kinematics::RobotModel;

mod cob4;
mod iiwa;

const TZ: f64 = -0.2;

fn table() -> Option<TableSpec> {
    Some(TableSpec {
        min: [0.2, -0.6],
        max: [0.95, 0.6],
        margin: 0.0,
    })
}

fn bx(name: &str, kind: BoxKind, c: [f64; 2], size: [f64; 3], margin: f64) -> SceneBox {
    SceneBox {
        name: name.into(),
        kind,
        centre: c,
        size,
        yaw: 0.0,
        margin,
        round: false,
    }
}

fn fixture(name: &str, desc: &str, robot: &str, scene: SceneSpec, path: FixturePath) -> Fixture {
    Fixture {
        name: name.into(),
        description: desc.into(),
        robot: robot.into(),
        arm: None,
        scene,
        path,
        held: None,
        ignore: vec![],
        expect: Expect {
            verdict: Verdict::Free,
            pair: None,
            segment: None,
        },
    }
}

fn dense_of(fx: &Fixture, d: &DenseSettings) -> DenseResult {
    dense_with(fx, d, true)
}

fn dense_with(fx: &Fixture, d: &DenseSettings, self_collision: bool) -> DenseResult {
    let file = PathBuf::from(&fx.name);
    let (g, scene, mut opts) = fx.prepare(&file).expect("prepare");
    opts.settings.self_collision = self_collision;
    match &fx.path {
        FixturePath::Tool(w) => {
            let poses: Vec<_> = w
                .iter()
                .map(|p| afford_kinematics::top_down_pose([p[0], p[1], p[2]].into(), p[3]))
                .collect();
            dense_tool_path(&g, &scene, &poses, &opts, d).expect("dense")
        }
        FixturePath::Arm(q) => {
            let arm = g.model().arms()[0].clone();
            let home = g.model().home().to_vec();
            let full: Vec<Vec<f64>> = q
                .iter()
                .map(|qa| {
                    let mut c = home.clone();
                    arm.insert(&mut c, qa);
                    c
                })
                .collect();
            dense_joint_path(&g, &scene, &full, &opts, d).expect("dense")
        }
        FixturePath::Robot(q) => dense_joint_path(&g, &scene, q, &opts, d).expect("dense"),
    }
}

fn segments(fx: &Fixture) -> usize {
    match &fx.path {
        FixturePath::Tool(w) => w.len() - 1,
        FixturePath::Arm(q) | FixturePath::Robot(q) => q.len() - 1,
    }
}

/// Sets the expectation from the dense reference; returns false (and says
/// why) when the fast check disagrees.
fn settle(fx: &mut Fixture) -> bool {
    let d = dense_of(fx, &DenseSettings::default());
    match &d.first_hit {
        None => {
            fx.expect = Expect {
                verdict: Verdict::Free,
                pair: None,
                segment: None,
            }
        }
        Some((t, a, b, _)) => {
            let n = segments(fx).max(1);
            fx.expect = Expect {
                verdict: Verdict::Collides,
                pair: Some([strip(a), strip(b)]),
                segment: Some((t.floor() as usize).min(n - 1)),
            }
        }
    }
    let file = PathBuf::from(&fx.name);
    let (g, scene, opts) = fx.prepare(&file).expect("prepare");
    let v = fx.check(&g, &scene, &opts, &file).expect("check");
    let ok = v.is_free() != d.collides();
    println!(
        "{:<40} dense: {} (min slack {:.4} m {:?}) fast: {}",
        fx.name,
        d.first_hit.as_ref().map_or("free".to_string(), |h| format!(
            "{} vs {} at t={:.3}",
            h.1, h.2, h.0
        )),
        d.min_slack,
        d.min_pair,
        v.first().map_or("free".to_string(), |c| c.to_string())
    );
    ok
}

fn strip(s: &str) -> String {
    s.split('#').next().unwrap_or(s).to_string()
}

/// Closest approach of the path to the scene, finely sampled.
fn closest(fx: &Fixture) -> DenseResult {
    dense_with(
        fx,
        &DenseSettings {
            step_m: 1e-5,
            step_rad: 2e-5,
            stop_at_first: false,
        },
        false,
    )
}

/// Two fixtures from one: the box `name`'s margin set to the exact closest
/// approach +1 mm (collides) and -1 mm (free).
fn graze(base: Fixture, name: &str, out: &mut Vec<Fixture>) {
    let c = closest(&base);
    assert_eq!(
        c.min_pair.1, name,
        "{}: closest pair is {:?}",
        base.name, c.min_pair
    );
    let idx = base
        .scene
        .boxes
        .iter()
        .position(|b| b.name == name)
        .unwrap();
    let m0 = base.scene.boxes[idx].margin;
    let dmin = c.min_slack + m0;
    for (suffix, delta, word) in [
        ("free-by-1mm", -0.001, "outside"),
        ("hit-by-1mm", 0.001, "inside"),
    ] {
        let mut f = base.clone();
        f.name = format!("{}-{suffix}", base.name);
        f.description = format!(
            "{} Closest approach to '{name}' is {:.5} m (dense, 10 um / 2e-5 rad); margin set to {:.5} m so the path stays 1 mm {word} the perimeter.",
            base.description,
            dmin,
            dmin + delta
        );
        f.scene.boxes[idx].margin = dmin + delta;
        out.push(f);
    }
}

/// A scene on the iiwa's table with `boxes`.
fn scene(boxes: Vec<SceneBox>) -> SceneSpec {
    SceneSpec {
        table_z: TZ,
        table: table(),
        boxes,
    }
}

/// A tool path through waypoints `[x, y, z, yaw]`.
fn tool(w: &[[f64; 4]]) -> FixturePath {
    FixturePath::Tool(w.to_vec())
}

fn main() {
    let out_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/collision");
    std::fs::create_dir_all(&out_dir).unwrap();
    let iiwa = RobotModel::builtin("kuka_iiwa14").unwrap();
    let cob = RobotModel::builtin("care_o_bot4").unwrap();
    let mut fx: Vec<Fixture> = Vec::new();
    iiwa::tool_paths(&mut fx);
    iiwa::joint_paths(&iiwa, &mut fx);
    cob4::fixtures(&cob, &mut fx);

    // --- random cases (iiwa), verdicts from the dense reference -----------
    let mut taken = 0;
    for seed in 0..200u64 {
        if taken >= 10 {
            break;
        }
        let case = random_case(&iiwa, 7_000 + seed);
        let mut f = fixture(
            &format!("random-iiwa-{}", 7_000 + seed),
            "Random scene and joint path (bench::random_case); verdict from dense sampling.",
            "kuka_iiwa14",
            case.scene,
            FixturePath::Robot(case.path),
        );
        if let Some(a) = case.attached {
            f.held = Some(HeldSpec {
                name: a.name,
                size: [
                    2.0 * a.half_extents[0],
                    2.0 * a.half_extents[1],
                    2.0 * a.half_extents[2],
                ],
                offset: [0.0, 0.0, 0.02],
            });
        }
        if settle(&mut f) {
            write(&out_dir, &f);
            taken += 1;
        }
    }

    let mut bad = 0;
    for mut f in fx {
        if settle(&mut f) {
            write(&out_dir, &f);
        } else {
            println!(
                "  !! fast check disagrees with dense on {}; not written",
                f.name
            );
            bad += 1;
        }
    }
    if bad > 0 {
        std::process::exit(1);
    }
}

fn write(dir: &std::path::Path, f: &Fixture) {
    let text = serde_saphyr::to_string(f).unwrap();
    let header = format!(
        "# Collision regression fixture, generated by collision/examples/gen_fixtures.rs.\n# {}\n",
        f.description
    );
    std::fs::write(dir.join(format!("{}.yaml", f.name)), header + &text).unwrap();
}
