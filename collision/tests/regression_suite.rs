//! Runs every fixture in `tests/collision/*.yaml` (repo root) through the fast
//! check and compares with its expected verdict. One line per fixture.
//! Adding a fixture = dropping a file in that directory.

use std::path::PathBuf;

use afford_collision::{fixture_files, run_fixture};

#[test]
fn collision_regression_suite() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/collision");
    let files = fixture_files(&dir).expect("fixture directory");
    assert!(
        files.len() >= 30,
        "only {} fixtures in {}",
        files.len(),
        dir.display()
    );
    let mut failed = Vec::new();
    for f in &files {
        match run_fixture(f) {
            Ok(o) => {
                println!("{}", o.summary);
                if !o.passed {
                    failed.push(o.name);
                }
            }
            Err(e) => {
                println!("ERR  {e}");
                failed.push(f.display().to_string());
            }
        }
    }
    println!("{} fixtures, {} failed", files.len(), failed.len());
    assert!(failed.is_empty(), "failed: {failed:?}");
}

#[test]
fn bad_fixture_is_a_typed_error_naming_the_file() {
    let dir = std::env::temp_dir().join("afford-collision-bad-fixture");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("bad.yaml");
    std::fs::write(&file, "name: x\nrobot: kuka_iiwa14\nscene: {table_z: 0}\npath: {tool: [[0,0,0,0]]}\nexpect: {verdict: maybe}\n").unwrap();
    let e = run_fixture(&file).unwrap_err().to_string();
    assert!(e.contains("bad.yaml"), "{e}");
    std::fs::write(&file, "name: x\nrobot: no_such_robot\nscene: {table_z: 0}\npath: {tool: [[0,0,0,0]]}\nexpect: {verdict: free}\n").unwrap();
    let e = run_fixture(&file).unwrap_err().to_string();
    assert!(e.contains("bad.yaml") && e.contains("robot"), "{e}");
}
