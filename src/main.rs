//! The `talus` binary: parse arguments → run → exit code (see cli/mod.rs).

fn main() -> std::process::ExitCode {
    cli::main()
}

mod cli;
