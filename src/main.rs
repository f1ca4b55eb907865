//! The `talus` binary: parse arguments → run → exit code (see cli.rs).

fn main() -> std::process::ExitCode {
    talus_cli::main()
}

#[path = "cli.rs"]
mod talus_cli;
