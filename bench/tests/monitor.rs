//! The monitor benchmark's small run (`afford bench monitor`, relevance by
//! construction): every relevant perturbation is detected and no
//! irrelevant one triggers.

use afford_bench::monitor::{MonitorBenchConfig, run};

#[test]
fn monitor_relevant_always_detected_irrelevant_never_triggers() {
    let report = run(
        &MonitorBenchConfig {
            scenes: 4,
            seed: 7,
            only: None,
        },
        |_| {},
        None,
    );
    assert!(report.relevant >= 20, "{report:?}");
    assert!(report.irrelevant >= 5, "{report:?}");
    assert_eq!(report.detected, report.relevant, "{report:?}");
    assert_eq!(report.false_triggers, 0, "{report:?}");
}
