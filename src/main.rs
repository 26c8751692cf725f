//! The `softarm` command line. See README.md for the commands.

fn main() -> std::process::ExitCode {
    softarm::cli::main()
}
