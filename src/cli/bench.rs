//! `afford bench …`: benchmarks with a progress bar on a terminal.

use std::io::IsTerminal;

use afford_planner::bench::cql::{self, CqlBenchConfig};
use indicatif::{ProgressBar, ProgressStyle};

use super::{BenchCqlArgs, ExitKind, Failure};

pub fn cql(args: &BenchCqlArgs) -> Result<(), Failure> {
    if args.scenarios == 0 {
        return Err(Failure::new(
            ExitKind::BadInput,
            "--scenarios must be at least 1",
        ));
    }
    let config = CqlBenchConfig {
        scenarios: args.scenarios,
        seed: args.seed,
        ..Default::default()
    };
    let bar = progress_bar(args.scenarios as u64, "scenes");
    let report = cql::run(&config, |done| bar.set_position(done as u64));
    bar.finish_and_clear();
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&report).expect("report serialises")
        );
    } else {
        print!("{}", report.table());
    }
    Ok(())
}

/// A progress bar on stderr when it is a terminal, hidden otherwise.
fn progress_bar(len: u64, unit: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    let template = format!("{{bar:40}} {{pos}}/{{len}} {unit} ({{eta}} left)");
    bar.set_style(
        ProgressStyle::with_template(&template).unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}
