//! A library user does not get the command's dependencies: with
//! `default-features = false` the `afford` crate depends on neither clap,
//! indicatif nor plotters (docs/decisions.md "The command is a feature").

use std::process::Command;

/// The names of `afford`'s normal dependencies, all levels, for `features`.
fn dependency_names(features: &[&str]) -> Vec<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let output = Command::new(cargo)
        .args([
            "tree",
            "--offline",
            "-p",
            "afford",
            "-e",
            "normal",
            "--prefix",
            "none",
        ])
        .args(features)
        .current_dir(crate::util::repo())
        .output()
        .expect("cargo tree runs");
    assert!(
        output.status.success(),
        "cargo tree: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout)
        .expect("UTF-8")
        .lines()
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .collect()
}

#[test]
fn library_without_default_features_pulls_in_no_cli_dependencies() {
    const CLI: [&str; 3] = ["clap", "indicatif", "plotters"];
    let library = dependency_names(&["--no-default-features"]);
    assert!(library.iter().any(|d| d == "afford-planner"), "{library:?}");
    for name in CLI {
        assert!(!library.iter().any(|d| d == name), "{name} in {library:?}");
    }
    // The same query sees them with the default features: it can fail.
    let command = dependency_names(&[]);
    for name in CLI {
        assert!(command.iter().any(|d| d == name), "{name} missing");
    }
}
