//! The `whet` command-line tool. Exit codes: 0 success; 1 any other failure (an output that
//! cannot be written, an internal error); 2 an input that cannot be read (not a mesh,
//! truncated, non-finite coordinates, out-of-range indices, a corrupt stream) or a usage error.

// The swing encoder's `--json` object is one `json!` with nested arrays of objects: past
// the default recursion limit of the macro.
#![recursion_limit = "256"]

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            eprintln!("whet: {}", cli::error_chain(&failure.error));
            ExitCode::from(failure.code)
        }
    }
}
