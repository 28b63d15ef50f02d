//! The `afford` command: a thin layer over the library crates. It parses
//! arguments, calls the library and turns outcomes into exit codes:
//! 0 planned, 1 could not plan (reason on stderr), 2 bad input, 3 the
//! result could not be written. Nothing is printed with `print!` or
//! `eprintln!` (they panic on a closed or full stream): the lints below
//! keep every line going through `cli::output`.

#![cfg_attr(not(test), deny(clippy::print_stdout, clippy::print_stderr))]

use std::process::ExitCode;

use clap::Parser;

mod cli;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            cli::output::note(format_args!("afford: {}", failure.message));
            ExitCode::from(failure.code as u8)
        }
    }
}
