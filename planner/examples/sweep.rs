use afford_planner::LearnerSettings;
use afford_planner::bench::cql::{CqlBenchConfig, run};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut s = LearnerSettings::default();
    for kv in &args[1..] {
        let (k, v) = kv.split_once('=').unwrap();
        match k {
            "lr" => s.learning_rate = v.parse().unwrap(),
            "g" => s.discount = v.parse().unwrap(),
            "eps" => s.epsilon = v.parse().unwrap(),
            "win" => s.convergence_window = v.parse().unwrap(),
            "move" => s.reward_move = v.parse().unwrap(),
            "goal" => s.reward_goal = v.parse().unwrap(),
            "drop" => s.reward_drop = v.parse().unwrap(),
            "grasp" => s.reward_grasp = v.parse().unwrap(),
            "bias" => s.distance_bias = v.parse().unwrap(),
            "replay" => s.replay = v.parse().unwrap(),
            "ep" => s.episode_steps = v.parse().unwrap(),
            "max" => s.max_steps = v.parse().unwrap(),
            _ => panic!("{k}"),
        }
    }
    for seed in [1u64, 2] {
        let r = run(
            &CqlBenchConfig {
                scenarios: 200,
                seed,
                settings: s.clone(),
            },
            |_| {},
        );
        println!(
            "seed {seed} solvable {} cql ok {:.3} med {:.3}ms mean {:.3}ms steps {:.0} len {:.3} | ql ok {:.3} len {:.3}",
            r.solvable,
            r.cql.success_rate,
            r.cql.median_ms,
            r.cql.mean_ms,
            r.cql.mean_steps,
            r.cql.mean_length_over_optimal,
            r.ql.success_rate,
            r.ql.mean_length_over_optimal
        );
    }
}
