//! The `afford` command: a thin layer over the library crates. It parses
//! arguments, calls the library and turns outcomes into exit codes:
//! 0 planned, 1 could not plan (reason on stderr), 2 bad input.

use std::process::ExitCode;

use clap::Parser;

mod cli;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            eprintln!("afford: {}", failure.message);
            ExitCode::from(failure.code as u8)
        }
    }
}
