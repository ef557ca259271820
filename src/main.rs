//! `survey`: the command-line face of robot-survey. A thin layer: every command calls a
//! library function that returns data, then formats it (see `robot_survey::report`).

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
