//! Home and park for `robots init`. Home: the SRDF group state named like
//! home or ready, when it is collision-free; else the first arm's tool
//! pointing down over the centre of the suggested table region at carry
//! height (0.25 m above the table), the IK solution (of up to
//! [`HOME_CANDIDATES`]) farthest inside the joint limits. Finger joints
//! open. Park: the SRDF group state named like park or rest, else home.

use afford_kinematics::draft::{Draft, Postures};
use afford_kinematics::{CameraSetup, RobotModel, Vec3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::reach::Reacher;

/// Collision-free IK solutions compared for home.
pub const HOME_CANDIDATES: usize = 8;
/// Carry height above the table of the home posture's tool, m.
pub const HOME_HEIGHT: f64 = 0.25;

/// Chooses home and park (module docs); one guess line each.
pub fn choose(
    model: &RobotModel,
    draft: &Draft,
    camera: Option<&CameraSetup>,
    guesses: &mut Vec<String>,
) -> Result<Postures, String> {
    let reacher = Reacher::new(model, camera)?;
    let named = |words: &[&str]| {
        (draft.states.iter()).find(|(n, _)| {
            let n = n.to_ascii_lowercase();
            words.iter().any(|w| n.contains(w))
        })
    };
    let apply = |values: &[(String, f64)]| {
        let mut q = model.home().to_vec();
        for (name, v) in values {
            if let Some(i) = model.joint_index(name)
                && model.joints()[i].within(*v, 1e-9)
            {
                q[i] = *v;
            }
        }
        q
    };
    let mut home = None;
    let mut home_source = String::new();
    if let Some((name, values)) = named(&["home", "ready"]) {
        let q = apply(values);
        match reacher.free(&q) {
            true => {
                home_source = format!("Home: the SRDF group_state '{name}'.");
                home = Some(q);
            }
            false => guesses.push(format!(
                "home: the SRDF group_state '{name}' touches the table or the robot itself; not used"
            )),
        }
    }
    if home.is_none() {
        (home, home_source) = ik_home(model, draft, &reacher, camera, guesses);
    }
    let home = home.unwrap_or_else(|| model.home().to_vec());
    let park_source;
    let park: Vec<Vec<(String, f64)>> = match named(&["park", "rest", "transport"]) {
        Some((name, values)) => {
            park_source = format!("Park: the SRDF group_state '{name}'.");
            let q = apply(values);
            model
                .arms()
                .iter()
                .map(|a| by_name(model, &q, &a.joint_indices))
                .collect()
        }
        None => {
            park_source = "Park: home (the SRDF names no park posture).".into();
            guesses.push(
                "park: each arm's home values (no SRDF group_state named like park or rest)".into(),
            );
            model
                .arms()
                .iter()
                .map(|a| by_name(model, &home, &a.joint_indices))
                .collect()
        }
    };
    let all: Vec<usize> = (0..model.joints().len()).collect();
    Ok(Postures {
        home: by_name(model, &home, &all),
        home_source,
        park,
        park_source,
    })
}

/// Home by IK over the table region's centre (module docs).
fn ik_home(
    model: &RobotModel,
    draft: &Draft,
    reacher: &Reacher,
    camera: Option<&CameraSetup>,
    guesses: &mut Vec<String>,
) -> (Option<Vec<f64>>, String) {
    let Some(c) = camera else {
        guesses.push("home: every arm joint at 0 clamped into its limits (no table region in reach to point over)".into());
        return (
            None,
            "Home: every arm joint at 0 clamped into its limits.".into(),
        );
    };
    let (x, y) = c.point(f64::from(c.width) / 2.0, f64::from(c.height) / 2.0);
    let p = Vec3::new(x, y, c.table_z + HOME_HEIGHT);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let arm = &model.arms()[0];
    let solutions = reacher.reach_all(0, p, &mut rng, HOME_CANDIDATES);
    let cost = |q: &[f64]| -> f64 {
        (arm.joint_indices.iter())
            .map(|&i| {
                let j = &model.joints()[i];
                match j.is_bounded() && j.upper > j.lower {
                    true => ((q[i] - j.mid()) / ((j.upper - j.lower) / 2.0)).powi(2),
                    false => 0.0,
                }
            })
            .sum()
    };
    let best = (solutions.into_iter()).min_by(|a, b| cost(a).total_cmp(&cost(b)));
    let text = format!(
        "Home: the tool pointing down over the table region's centre ({x:.3}, {y:.3}) at {HOME_HEIGHT} m above the table, the IK solution farthest inside the limits."
    );
    match best {
        Some(q) => {
            let fingers = match draft.finger_open.is_empty() {
                true => "",
                false => "; finger joints open",
            };
            guesses.push(format!("home: by IK, tool down at ({x:.3}, {y:.3}, {:.3}), the solution farthest inside the joint limits{fingers}", p.z));
            (Some(q), text)
        }
        None => {
            guesses.push("home: no collision-free IK solution over the table centre; every joint at 0 clamped into its limits".into());
            (
                None,
                "Home: every arm joint at 0 clamped into its limits.".into(),
            )
        }
    }
}

fn by_name(model: &RobotModel, q: &[f64], indices: &[usize]) -> Vec<(String, f64)> {
    (indices.iter())
        .map(|&i| (model.joints()[i].name.clone(), q[i]))
        .collect()
}
