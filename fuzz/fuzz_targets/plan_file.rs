//! `afford check`'s plan reader on arbitrary text: it must return a plan or
//! an error naming the field, never panic, hang or allocate beyond its
//! documented bounds. Run: `cargo +nightly fuzz run plan_file`.

#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = afford_check::read_plan(text);
    }
});
