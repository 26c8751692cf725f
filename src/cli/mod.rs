//! The `softarm` command line: its arguments and commands (README.md
//! lists them). In the library, so that the binary is its `main` alone:
//! the binary is compiled after the generated models, and all else
//! compiles beside them.

mod animate;
mod commands;
mod export;
mod fit;
mod sweep;
mod tables;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "softarm",
    version,
    about = "Soft robot arm dynamics: derive, compile, simulate."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the compiled-in models with their degrees of freedom.
    List {
        #[arg(long)]
        json: bool,
    },
    /// Regenerate generated/ from models/ (or check that it is current).
    Derive(commands::DeriveArgs),
    /// Simulate a model; writes trajectory.csv and summary.json.
    Simulate(commands::SimulateArgs),
    /// Print M(q), h(q, qd, t), the tip position and energies at a state.
    Eom(commands::EomArgs),
    /// Time derivation and kernel evaluation in-process.
    Bench(commands::BenchArgs),
    /// Static equilibrium under gravity and the applied loads.
    Static(commands::StaticArgs),
    /// Natural frequencies (and mode shapes) about the static equilibrium.
    Modes(commands::ModesArgs),
    /// Stiffness analysis: eigenvalues, stiffness ratio, recommended solver.
    Inspect(commands::InspectArgs),
    /// A parameter study: simulate, static or modes for every combination
    /// of --vary values, in parallel; writes sweep.csv and sweep.png.
    Sweep(sweep::SweepArgs),
    /// Simulate and show the arm: animation.gif (a shaded tube from a
    /// view, the time, the tip path, the inputs) and viewer.html (an
    /// interactive 3D view in one file).
    Animate(animate::AnimateArgs),
    /// The state-space model (A, B, C, D) about an equilibrium, for
    /// controller design: x = (q, qd), u the named input channels, y the
    /// tip.
    Linearize(commands::LinearizeArgs),
    /// The largest fixed step that keeps the tip within a tolerance of a
    /// tight reference run, for fixed-step use (a controller's loop).
    FixedStep(commands::FixedStepArgs),
    /// Fit model values to the model's [compare] record (least squares on
    /// the tip, exact-Jacobian sensitivities); writes fit.json,
    /// fitted.toml and fit.png.
    Fit(fit::FitArgs),
    /// Export the equations: a C99 library (one header, one source, libm
    /// alone) with the state derivative, its Jacobian, M and h, the
    /// outputs and the shape.
    Export(export::ExportArgs),
}

/// Parses the command line and runs its command.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::List { json } => commands::list(json),
        Command::Derive(a) => commands::derive(a),
        Command::Simulate(a) => commands::simulate(a),
        Command::Eom(a) => commands::eom(a),
        Command::Bench(a) => commands::bench(a),
        Command::Static(a) => commands::statics(a),
        Command::Modes(a) => commands::modes(a),
        Command::Inspect(a) => commands::inspect(a),
        Command::Sweep(a) => sweep::sweep(a),
        Command::Animate(a) => animate::animate(a),
        Command::Linearize(a) => commands::linearize(a),
        Command::FixedStep(a) => commands::fixed_step(a),
        Command::Fit(a) => fit::fit(a),
        Command::Export(a) => export::export(a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
