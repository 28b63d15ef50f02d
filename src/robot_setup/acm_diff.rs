//! The SRDF's `disable_collisions` against the derived allowed-collision
//! matrix: pairs the SRDF skips that the derivation checks, and pairs the
//! derivation skips (other than adjacent) that the SRDF does not name. One
//! line each, in the matrix's pair order then the SRDF's.

use std::collections::BTreeSet;

use afford_collision::AllowedCollisionMatrix;

fn key(a: &str, b: &str) -> (String, String) {
    match a <= b {
        true => (a.to_string(), b.to_string()),
        false => (b.to_string(), a.to_string()),
    }
}

/// The differences (module docs); empty when they agree.
pub fn differences(srdf: &[[String; 2]], matrix: &AllowedCollisionMatrix) -> Vec<String> {
    if srdf.is_empty() {
        return Vec::new();
    }
    let disabled: BTreeSet<(String, String)> = srdf.iter().map(|[a, b]| key(a, b)).collect();
    let mut out = Vec::new();
    let mut seen = BTreeSet::new();
    for p in &matrix.pairs {
        let k = key(&p.links[0], &p.links[1]);
        seen.insert(k.clone());
        let [a, b] = &p.links;
        match (disabled.contains(&k), p.reason) {
            (true, None) => out.push(format!(
                "SRDF disables [{a}, {b}]; the derived matrix checks it (min distance {:.3} m, in contact in {:.1} % of samples)",
                p.min_distance.unwrap_or(0.0),
                100.0 * p.contact_fraction.unwrap_or(0.0)
            )),
            (false, Some(r)) if r != afford_kinematics::AllowedReason::Adjacent => out.push(format!(
                "the derived matrix skips [{a}, {b}] ({}); the SRDF does not disable it",
                r.as_str()
            )),
            _ => {}
        }
    }
    for (a, b) in disabled.difference(&seen) {
        out.push(format!(
            "SRDF disables [{a}, {b}]: not a pair of the matrix (a link without collision geometry)"
        ));
    }
    out
}
