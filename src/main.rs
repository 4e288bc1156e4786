//! The `shadefit` command line: parse, call the library, print. Exit codes: 0 ok, 1 the job
//! failed, 2 bad input.

use clap::{Parser, Subcommand};
use shadefit::cli::{self, InputError, Paths};
use shadefit::fit::Objective;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "shadefit", version, about = "Integrate, fit, verify and emit shading-model approximations", after_help = shadefit::family::commands_help())]
struct Cli {
    /// Folder of fit specs.
    #[arg(long, global = true, default_value = "fits")]
    fits: PathBuf,
    /// Folder the emitted files go to.
    #[arg(long, global = true, default_value = "generated")]
    generated: PathBuf,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// A family's own command (listed below).
    #[command(external_subcommand)]
    Family(Vec<String>),
    /// Tables and fits known from the specs, with whether generated/ is up to date.
    List,
    /// Evaluate an integral (not a fit) at one point: QUANTITY name=value ...
    #[command(after_help = shadefit::family::eval_help())]
    Eval {
        /// The quantity to integrate (listed below with its parameters).
        quantity: String,
        /// Parameters as name=value, every parameter of the quantity once (or an alias).
        params: Vec<String>,
        /// Print one JSON object {"quantity", "params", "value", "error_estimate"} (RGB
        /// quantities: "value" is an array and "channels" names its entries).
        #[arg(long)]
        json: bool,
        /// Quantities whose family takes it: a profile file (e.g. a diffusion profile, a TOML
        /// file with a [profile] section or a CSV radial profile radius_mm,red,green,blue).
        #[arg(long)]
        profile: Option<PathBuf>,
        /// Quantities whose family takes it: the integration kernel (e.g. linear or radial).
        #[arg(long)]
        kernel: Option<String>,
    },
    /// Integrate, fit, verify and emit every spec (or the named ones) into generated/.
    Build {
        /// Comma-separated spec names.
        #[arg(long, value_delimiter = ',')]
        only: Vec<String>,
        /// Write nothing; fail if any generated file differs from what the specs and the
        /// committed coefficients produce.
        #[arg(long)]
        check: bool,
        /// Build only what this scene manifest (fits/scenes/NAME.toml) needs, skipping nodes
        /// whose inputs and files are unchanged since its last build.
        #[arg(long, conflicts_with_all = ["only", "check"])]
        scene: Option<PathBuf>,
        /// Rebuild every selected spec (with --scene: every reached node), even those whose
        /// last build is current (same input hash, files unchanged). The input hash covers
        /// the specs, not the code: after changing the code, build with --force.
        #[arg(long, conflicts_with = "check")]
        force: bool,
        /// Comma-separated outputs besides the WGSL modules, for every module: wgsl (the
        /// modules, always written), wgsl-plain, hlsl, glsl (450 core), glsl-es (ES 300), msl,
        /// spirv, c (a header of the constants), wesl (a WESL package: the modules and its
        /// wesl.toml). Specs may add their own ([emit] targets). With --scene: the scene module
        /// and every module it reaches.
        #[arg(long, value_delimiter = ',', value_parser = parse_target)]
        target: Vec<shadefit::emit::targets::Target>,
        /// K/N: compute shard K (0-based) of N of the cells of the named specs (default: every
        /// spec whose kind shards) into --shard-dir, writing nothing under generated/;
        /// `shadefit merge` combines the N shard files into what one build writes.
        #[arg(long, conflicts_with_all = ["scene", "check", "target"])]
        shard: Option<String>,
        /// Folder of the shard files.
        #[arg(long, default_value = "shards", requires = "shard")]
        shard_dir: PathBuf,
    },
    /// Combine shard files (`build --shard K/N`) into exactly the files one build writes.
    Merge {
        /// Shard files: every shard of each spec once.
        files: Vec<PathBuf>,
    },
    /// Fit a model to your own CSV data, from no start values.
    Fit {
        /// CSV file with a header row.
        #[arg(long)]
        data: PathBuf,
        /// Feature column(s), comma-separated.
        #[arg(long, value_delimiter = ',', required = true)]
        x: Vec<String>,
        /// Target column.
        #[arg(long)]
        y: String,
        /// `rational(m,n)` (total degree m over total degree n in the --x columns: every
        /// monomial of degree ≤ m over 1 + every monomial of degree 1..n; degrees ≤ 12, at most
        /// 64 coefficients) or a model spec TOML file (README "Spec files": the [model] keys
        /// plus `features`).
        #[arg(long)]
        model: String,
        /// lsq: least squares; minimax: the smallest maximum error; l4: Σ r⁴, between the two.
        #[arg(long, default_value = "lsq")]
        objective: Objective,
        /// Print the coefficients, errors and worst point as one JSON object.
        #[arg(long)]
        json: bool,
        /// Also emit the fit like a spec's into this folder: wgsl/NAME.wgsl, src/NAME.rs and
        /// json/NAME.json (the fit report, f32 coefficients, positivity bound), inputs clamped
        /// to the data's range (or --domain); refused unless the denominator is proven positive
        /// there.
        #[arg(long, value_name = "DIR")]
        emit: Option<PathBuf>,
        /// With --emit: more outputs, comma-separated (wgsl-plain, hlsl, glsl, glsl-es, msl, spirv, c, wesl: a WESL package of the module and its wesl.toml).
        #[arg(long, value_delimiter = ',', requires = "emit")]
        target: Vec<String>,
        /// With --emit: the module name (default: the CSV file's stem).
        #[arg(long, requires = "emit")]
        name: Option<String>,
        /// With --emit: the emitted function's name (default: the module name).
        #[arg(long, requires = "emit")]
        function: Option<String>,
        /// With --emit: the function's argument names, one per --x column (default: the columns).
        #[arg(long, value_delimiter = ',', requires = "emit")]
        args: Option<Vec<String>>,
        /// With --emit: the clamp box on some --x columns, COLUMN=LO:HI comma-separated (e.g.
        /// a=0:1,b=-2:2; finite bounds, LO < HI, containing the column's data); the others
        /// keep their data's range.
        #[arg(long, value_delimiter = ',', requires = "emit", value_name = "COLUMN=LO:HI")]
        domain: Vec<String>,
    },
    /// Print the fitting samples of one spec (grid points and the integral there).
    Samples {
        name: String,
        /// JSON with the model description (default: CSV).
        #[arg(long)]
        json: bool,
    },
    /// Write figures (PNG and SVG): the quantities, the published and refitted forms, error maps.
    Plot {
        /// Output folder.
        #[arg(long, default_value = "plots")]
        out: PathBuf,
    },
    /// Measure published tables and approximations against the integrals.
    Validate {
        #[arg(long)]
        json: bool,
        /// Families whose published constants to measure, comma-separated (default: all; see
        /// `shadefit families`).
        #[arg(long, value_delimiter = ',')]
        family: Vec<String>,
        /// Form specs (kind = "form") of --fits to measure, comma-separated (default: all; with
        /// --only and no --family, no family is measured).
        #[arg(long, value_delimiter = ',')]
        only: Vec<String>,
        /// Recompute every section instead of reading the cache of earlier runs with the same
        /// executable and inputs ($SHADEFIT_CACHE, else $XDG_CACHE_HOME/shadefit, else
        /// ~/.cache/shadefit); the cache is rewritten.
        #[arg(long)]
        no_cache: bool,
    },
    /// Measure a form spec (kind = "form": your own formula) against its integral on its grid,
    /// writing nothing; --refit also refits its constants.
    Measure {
        /// The form spec file.
        file: PathBuf,
        /// Refit every constant as `build` does and measure the refit too.
        #[arg(long)]
        refit: bool,
        #[arg(long)]
        json: bool,
    },
    /// Run time against error: integrators, fit solvers, tables against numpy/scipy, shader forms.
    Bench {
        /// The CI mode: fewer points and settings (under a minute).
        #[arg(long)]
        quick: bool,
        #[arg(long)]
        json: bool,
        /// Sections to run, comma-separated: integrators, fits, tables, builds, forms (default: all).
        #[arg(long, value_delimiter = ',')]
        only: Vec<String>,
        /// Families whose rows to run, comma-separated (default: all; see `shadefit families`).
        #[arg(long, value_delimiter = ',')]
        family: Vec<String>,
        /// Interpreter for the numpy/scipy side (default: tests/python/.venv, else python3);
        /// when given, a failure of that side fails the run.
        #[arg(long, conflicts_with = "no_python")]
        python: Option<PathBuf>,
        /// Skip the numpy/scipy side.
        #[arg(long)]
        no_python: bool,
    },
}

fn parse_target(s: &str) -> Result<shadefit::emit::targets::Target, String> {
    Ok(shadefit::emit::targets::parse_list(&[s])?[0])
}

/// The `--fits` folder the arguments name (`--fits DIR` or `--fits=DIR`, the last one wins),
/// or the default, before clap parses them.
fn fits_folder(args: impl Iterator<Item = std::ffi::OsString>) -> PathBuf {
    let mut out = PathBuf::from("fits");
    let mut args = args.skip(1);
    while let Some(a) = args.next() {
        if a == "--" {
            break;
        }
        if a == "--fits" {
            if let Some(v) = args.next() {
                out = PathBuf::from(v);
            }
        } else if let Some(v) = a.to_str().and_then(|s| s.strip_prefix("--fits=")) {
            out = PathBuf::from(v);
        }
    }
    out
}

fn main() -> ExitCode {
    // A closed pipe ends the process quietly, as it does other command-line tools (Rust ignores
    // SIGPIPE by default, and printing to a closed pipe would then panic).
    #[cfg(unix)]
    // SAFETY: called first in main, before any other thread exists; SIG_DFL is a valid handler.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // The lobe specs of the specs folder serve quantities (`eval NAME-albedo`, table specs of
    // them, `eval --help`): they are read before the arguments are parsed; an error in one is
    // reported by every command that reads the catalog.
    let lobes = cli::register_lobes(&fits_folder(std::env::args_os()));
    let cli = Cli::parse();
    let paths = Paths { fits: cli.fits, generated: cli.generated };
    let reads_catalog = !matches!(cli.command, Command::Family(_) | Command::Fit { .. });
    let result = cli::check_environment().and_then(|()| if reads_catalog { lobes } else { Ok(()) }).and_then(|()| match cli.command {
        Command::List => cli::list(&paths),
        Command::Family(args) => cli::family_command(&args),
        Command::Eval { quantity, params, json, profile: None, kernel: None } => cli::eval(&quantity, &params, json),
        Command::Eval { quantity, params, json, profile, kernel } => {
            cli::eval_with_options(&quantity, &params, json, profile.as_deref(), kernel.as_deref())
        }
        Command::Build { scene: Some(file), force, target, .. } => cli::build_scene(&paths, &file, force, &target),
        Command::Build { only, shard: Some(shard), shard_dir, .. } => cli::build_shard(&paths, &only, &shard, &shard_dir),
        Command::Build { only, check, force, target, .. } => cli::build(&paths, &only, check, force, &target),
        Command::Merge { files } => cli::merge(&paths, &files),
        Command::Fit { data, x, y, model, objective, json, emit, target, name, function, args, domain } => {
            let emit = emit.map(|dir| cli::FitEmit { dir, targets: target, name, function, args, domain });
            cli::fit_data(&data, &x, &y, &model, objective, json, emit.as_ref())
        }
        Command::Samples { name, json } => cli::samples(&paths, &name, json),
        Command::Plot { out } => cli::plot(&paths, &out),
        Command::Validate { json, family, only, no_cache } => cli::validate(&paths, &family, &only, json, no_cache),
        Command::Measure { file, refit, json } => cli::measure(&file, refit, json),
        Command::Bench { quick, json, only, family, python, no_python } => {
            cli::bench(&paths, &cli::BenchArgs { quick, json, only, family, python, no_python })
        }
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            if e.chain().any(|c| c.is::<InputError>()) { ExitCode::from(2) } else { ExitCode::from(1) }
        }
    }
}
