//! The `jitterid` binary.

fn main() -> std::process::ExitCode {
    jitterid_cli::run(std::env::args_os())
}
