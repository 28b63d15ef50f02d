//! Internal error text never reaches a user: statuses and refusals read in
//! the user's terms, not as Rust Debug output or internal field paths.

use afford_planner::timing::{LimitKind, LimitViolation, SolverOutcome, TimingError, TimingStatus};

fn assert_plain(text: &str) {
    for internal in [
        "SolverStopped",
        "NumericalError",
        "LimitViolated",
        "{",
        "half_extents",
    ] {
        assert!(!text.contains(internal), "{internal:?} in {text:?}");
    }
}

#[test]
fn solver_stopped_numerical_error_reads_in_user_terms() {
    for outcome in [
        SolverOutcome::NumericalError,
        SolverOutcome::Infeasible,
        SolverOutcome::LimitReached,
    ] {
        let text = TimingStatus::SolverStopped { outcome }.to_string();
        assert_plain(&text);
        assert!(text.contains("no time-optimal motion"), "{text}");
    }
}

#[test]
fn limit_violated_names_the_limit_in_words() {
    let status = TimingStatus::LimitViolated {
        violation: LimitViolation {
            kind: LimitKind::Acceleration,
            sample: 12,
            joint: 3,
            value: -5.5,
            limit: 5.0,
        },
    };
    let text = status.to_string();
    assert_plain(&text);
    assert!(
        text.contains("joint acceleration limit at sample 12"),
        "{text}"
    );
}

#[test]
fn too_many_samples_says_how_long_and_what_to_do() {
    let text = TimingError::TooManySamples {
        duration_s: 1000.0,
        rate_hz: 100.0,
        samples: 100_001.0,
    }
    .to_string();
    assert_plain(&text);
    assert!(
        text.contains("1000.0 s") && text.contains("at most 10000 samples"),
        "{text}"
    );
}
