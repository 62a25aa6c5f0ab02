//! `weft-surrogate`: regression and neural-network surrogates of a dependence x → y
//! (the paper's §4: girder parameters to fitted membrane parameters).

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use weft::surrogate::{self, Activation, Scale, Training};

#[derive(Parser)]
#[command(
    name = "weft-surrogate",
    version,
    about = "Regression and neural-network surrogates of x → y (the paper's §4, Fig. 6): train on a table, predict for new x",
    long_about = "train: splits the rows (seeded) into train, validation and test; fits a least-squares polynomial of the \
                  scaled inputs (log by default, mapped to [−1, 1]) whose degree k-fold cross-validation picks, and \
                  searches the paper's two-layer network (n₁ hidden neurons, tanh or logistic, linear output, inputs and \
                  outputs mapped to [−1, 1]) over n₁ × activation × restarts, each trained by Levenberg–Marquardt with \
                  early stopping on the validation rows. MSEs are in normalised output units (as MATLAB's toolbox reports \
                  them; the paper: 0.0333 at 11 tansig neurons). Writes OUT/surrogate.json (both surrogates: \
                  normalisation, coefficients, weights), OUT/search.parquet (one row per network trained) and \
                  OUT/split.parquet (every row, its part, both predictions). Deterministic for a --seed whatever \
                  --threads.\n\npredict: y for every row of a table of x (a warning for a row outside the training \
                  range).\n\nExamples:\n  \
                  weft-surrogate train --table sweep.parquet --inputs b_g,N_g --outputs G_m,s_m,rho_m --out runs/sur\n  \
                  weft-surrogate predict --surrogate runs/sur/surrogate.json --table new_x.parquet \\\n    \
                  --out pred.parquet"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Fit the regression and search the networks on a table of x and y.
    #[command(
        after_help = "Example:\n  weft-surrogate train --table sweep.parquet --inputs b_g,N_g \\\n    --outputs membrane.G12,membrane.s,membrane.rho --out runs/net"
    )]
    Train(Box<TrainArgs>),
    /// Predict y for a table of x with a trained surrogate.
    #[command(
        after_help = "Example:\n  weft-surrogate predict --surrogate runs/net/surrogate.json --x b_g=1.2e-3,N_g=7 \\\n    --out prediction.parquet"
    )]
    Predict(PredictArgs),
}

#[derive(clap::Args)]
struct TrainArgs {
    /// Training table (Parquet) with the input and output columns.
    #[arg(long)]
    table: PathBuf,
    /// Train on the rows where COLUMN equals VALUE (repeat), e.g. `match=position`.
    #[arg(long, value_name = "COLUMN=VALUE")]
    filter: Vec<String>,
    /// Input columns x, comma-separated.
    #[arg(long, value_delimiter = ',', required = true)]
    inputs: Vec<String>,
    /// Output columns y, comma-separated.
    #[arg(long, value_delimiter = ',', required = true)]
    outputs: Vec<String>,
    /// Scale of the inputs before they are mapped to [−1, 1].
    #[arg(long, value_enum, default_value = "log")]
    input_scale: Scale,
    /// Scale of the outputs before they are mapped to [−1, 1].
    #[arg(long, value_enum, default_value = "linear")]
    output_scale: Scale,
    /// Fraction of the rows held for early stopping (validation).
    #[arg(long, default_value_t = 0.15)]
    validation: f64,
    /// Fraction of the rows held out for the test MSE.
    #[arg(long, default_value_t = 0.15)]
    test: f64,
    /// Hidden neurons searched: MIN..MAX (the paper: 3..17).
    #[arg(long, default_value = "3..17", value_parser = parse_range)]
    hidden: (usize, usize),
    /// Activations searched, comma-separated.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "tanh,logistic"
    )]
    activations: Vec<Activation>,
    /// Random initialisations per (n₁, activation).
    #[arg(long, default_value_t = 5)]
    restarts: usize,
    /// Highest polynomial degree the cross-validation tries.
    #[arg(long, default_value_t = 4)]
    max_degree: usize,
    /// Folds of the cross-validation.
    #[arg(long, default_value_t = 5)]
    folds: usize,
    /// Epochs without a better validation MSE before a training stops.
    #[arg(long, default_value_t = 6)]
    max_fail: usize,
    /// Epochs (accepted Levenberg–Marquardt steps) at most.
    #[arg(long, default_value_t = 1000)]
    max_epochs: usize,
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Worker threads (0: all cores); the results do not depend on it.
    #[arg(long, default_value_t = 0)]
    threads: usize,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
}

#[derive(clap::Args)]
struct PredictArgs {
    /// surrogate.json from `weft-surrogate train`.
    #[arg(long)]
    surrogate: PathBuf,
    /// Table (Parquet) with the surrogate's input columns.
    #[arg(long, conflicts_with = "x", required_unless_present = "x")]
    table: Option<PathBuf>,
    /// One x instead of a table: NAME=VALUE per input, comma-separated.
    #[arg(long, value_delimiter = ',')]
    x: Vec<String>,
    /// Predictions table (Parquet).
    #[arg(long, required_unless_present = "print_flags")]
    out: Option<PathBuf>,
    /// Print the prediction for the one x on stdout as command-line flags, from this
    /// surrogate (network or regression), renamed by --flag: for a generator, e.g.
    /// `weft-weave membrane $(weft-surrogate predict ... --print-flags network
    /// --flag G_m=--shear-modulus --flag s_m=--thickness --flag rho_m=--density)`.
    #[arg(long, value_parser = ["network", "regression"])]
    print_flags: Option<String>,
    /// OUTPUT=--FLAG: the flag an output is printed as (repeat; default `--OUTPUT`).
    #[arg(long = "flag", value_name = "OUTPUT=--FLAG")]
    flags: Vec<String>,
}

fn parse_range(s: &str) -> Result<(usize, usize), String> {
    let bad = || format!("`{s}`: expected MIN..MAX neurons, e.g. 3..17");
    let (a, b) = s.split_once("..").ok_or_else(bad)?;
    Ok((
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    ))
}

fn main() -> ExitCode {
    weft::cli::main(run)
}

fn run() -> anyhow::Result<ExitCode> {
    match Cli::parse().command {
        Command::Train(a) => {
            let a = *a;
            let r = surrogate::train(&surrogate::TrainConfig {
                table: a.table,
                filter: a.filter,
                inputs: a.inputs,
                outputs: a.outputs,
                input_scale: a.input_scale,
                output_scale: a.output_scale,
                validation: a.validation,
                test: a.test,
                hidden_min: a.hidden.0,
                hidden_max: a.hidden.1,
                activations: a.activations,
                restarts: a.restarts,
                max_degree: a.max_degree,
                folds: a.folds,
                seed: a.seed,
                training: Training {
                    max_fail: a.max_fail,
                    max_epochs: a.max_epochs,
                    ..Default::default()
                },
                threads: a.threads,
                out: a.out.clone(),
            })?;
            let s = &r.surrogate;
            eprintln!(
                "weft-surrogate: {} train, {} validation, {} test rows; regression degree {} test MSE {:.4e}; \
                 {} networks, chosen n1 = {} {} test MSE {:.4e} (validation {:.4e}); min test MSE of the search {:.4e} -> {}",
                r.rows[0],
                r.rows[1],
                r.rows[2],
                s.regression.degree,
                s.regression_test_mse,
                r.experiments.len(),
                s.network.hidden,
                s.network.activation.name(),
                s.network_test_mse,
                s.network_validation_mse,
                r.experiments
                    .iter()
                    .map(|e| e.test_mse)
                    .fold(f64::INFINITY, f64::min),
                a.out.display()
            );
        }
        Command::Predict(a) => {
            let r = surrogate::predict(&surrogate::PredictConfig {
                surrogate: a.surrogate,
                table: a.table,
                x: a.x,
                out: a.out.clone(),
            })?;
            for w in &r.warnings {
                eprintln!("weft-surrogate: warning: {w}");
            }
            if let Some(which) = &a.print_flags {
                if r.rows != 1 {
                    anyhow::bail!(
                        "--print-flags prints one prediction; the table has {} rows (expected one x: use --x)",
                        r.rows
                    );
                }
                let y = if which == "network" {
                    &r.network[0]
                } else {
                    &r.regression[0]
                };
                let mut parts = vec![];
                for (k, name) in r.outputs.iter().enumerate() {
                    let flag = a
                        .flags
                        .iter()
                        .find_map(|f| {
                            f.split_once('=')
                                .filter(|p| p.0 == name)
                                .map(|p| p.1.to_string())
                        })
                        .unwrap_or_else(|| format!("--{name}"));
                    parts.push(format!("{flag} {:e}", y[k]));
                }
                println!("{}", parts.join(" "));
            }
            if let Some(out) = &a.out {
                eprintln!("weft-surrogate: {} rows -> {}", r.rows, out.display());
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}
