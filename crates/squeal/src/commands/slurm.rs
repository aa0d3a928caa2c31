//! `squeal slurm map|reproduce|sweep … --tasks N [--partition P] [--time T]
//! [--cpus-per-task C] [--jobs DIR] [--submit]`: a SLURM job array that
//! computes a map (or the thesis's 40 sets) in N shards, and a merge job
//! that depends on it.
//!
//! The scripts are [`squeal_files::slurm`]'s. Writes into the jobs folder (default `OUT-slurm`):
//! - `array.sh`: `#SBATCH --array=0-(N-1)`; task K runs `squeal map …
//!   --shard K/N --out JOBS/shard-K/map` (`squeal reproduce …`: `…/reproduce`) with `RAYON_NUM_THREADS` set to
//!   `SLURM_CPUS_PER_TASK`; its log is `JOBS/shard-K.log`. Each shard has a
//!   parent folder of its own: staging removes leftovers of dead processes
//!   by PID in the parent folder, and PIDs of other nodes mean nothing here;
//! - `merge.sh`: `squeal merge JOBS/shard-{0..N-1}/map --out OUT` (or `…/reproduce`), log
//!   `JOBS/merge.log`.
//!
//! With `--submit` it runs `sbatch --parsable array.sh`, then `sbatch
//! --parsable --dependency=afterok:ID merge.sh`, and prints both job ids;
//! without, it prints those two commands. Task K alone is rerun with
//! `sbatch --array=K JOBS/array.sh` (then `sbatch JOBS/merge.sh`).

use crate::commands::map::{prepare, MapArgs};
use crate::commands::reproduce::ReproduceArgs;
use crate::commands::sweep::SweepArgs;
use crate::run::RunError;
use clap::{Args, Subcommand};
use squeal_files::slurm::{check_job, check_tasks, submit, write_scripts, Job};
use squeal_study::scenario::InputError;
use std::path::{Path, PathBuf};

/// What `squeal slurm` prepares.
#[derive(Subcommand, Debug)]
pub enum SlurmCmd {
    /// A stability map as a job array of shards and a dependent merge job.
    Map(SlurmMapArgs),
    /// The thesis re-done (`squeal reproduce`) as a job array of shards of
    /// its 40 sets and a dependent merge job that writes the report.
    Reproduce(SlurmReproduceArgs),
    /// An eigenvalue sweep (`squeal sweep`) as a job array of contiguous
    /// slices and a dependent merge job.
    Sweep(SlurmSweepArgs),
}

/// Arguments of `squeal slurm sweep`: those of `sweep` and the job's.
#[derive(Args, Debug)]
pub struct SlurmSweepArgs {
    #[command(flatten)]
    sweep: SweepArgs,
    #[command(flatten)]
    job: JobArgs,
}

/// Arguments of `squeal slurm map`: those of `map` and the job's.
#[derive(Args, Debug)]
pub struct SlurmMapArgs {
    #[command(flatten)]
    map: MapArgs,
    #[command(flatten)]
    job: JobArgs,
}

/// Arguments of `squeal slurm reproduce`: those of `reproduce` and the job's.
#[derive(Args, Debug)]
pub struct SlurmReproduceArgs {
    #[command(flatten)]
    rep: ReproduceArgs,
    #[command(flatten)]
    job: JobArgs,
}

/// The job array's settings, the same for every command.
#[derive(Args, Debug)]
pub struct JobArgs {
    /// Number of array tasks (shards).
    #[arg(long)]
    tasks: usize,
    /// SLURM partition (default: the cluster's default).
    #[arg(long)]
    partition: Option<String>,
    /// Time limit of each task, in SLURM's format (e.g. 2:00:00).
    #[arg(long)]
    time: Option<String>,
    /// CPUs of each task; squeal's threads follow SLURM_CPUS_PER_TASK.
    #[arg(long)]
    cpus_per_task: Option<usize>,
    /// Folder for the scripts, the shards and the logs (default: OUT-slurm).
    #[arg(long)]
    jobs: Option<PathBuf>,
    /// Submit both jobs with sbatch and print their ids.
    #[arg(long)]
    submit: bool,
}

/// The `squeal map …` arguments that fix the study (not --out, --shard).
fn map_args(a: &MapArgs) -> Vec<String> {
    let mut v = vec!["map".to_string(), a.scenario.scenario.clone()];
    for s in &a.scenario.sets {
        v.extend(["--set".into(), s.clone()]);
    }
    v.extend(["--x".into(), a.x.clone(), "--y".into(), a.y.clone()]);
    if a.log_x {
        v.push("--log-x".into());
    }
    if a.log_y {
        v.push("--log-y".into());
    }
    if a.transient {
        v.push("--transient".into());
    }
    if let Some(d) = a.duration {
        v.extend(["--duration".into(), format!("{d}")]);
    }
    v
}

/// The `squeal sweep …` arguments that fix the study (not --out, --shard, --json).
fn sweep_args(a: &SweepArgs) -> Vec<String> {
    let mut v = vec!["sweep".to_string(), a.scenario.scenario.clone()];
    for s in &a.scenario.sets {
        v.extend(["--set".into(), s.clone()]);
    }
    v.extend(["--param".into(), a.param.clone()]);
    v
}

/// The `squeal reproduce …` arguments that fix the study (not --out, --shard).
fn reproduce_args(a: &ReproduceArgs) -> Vec<String> {
    let mut v = vec![
        "reproduce".to_string(),
        "--duration-scale".into(),
        format!("{}", a.duration_scale),
    ];
    if a.no_figures {
        v.push("--no-figures".into());
    }
    v
}

/// Run the command.
pub fn run(cmd: SlurmCmd) -> Result<(), RunError> {
    match cmd {
        SlurmCmd::Map(a) => {
            check_job(&job(&a.job), a.map.shard.is_some(), "map")?;
            let study = prepare(&a.map)?;
            let (sc, points) = (&study.sc, study.grid_points());
            check_tasks(a.job.tasks, points, "points of the map")?;
            let out = a
                .map
                .out
                .clone()
                .unwrap_or_else(|| PathBuf::from("out").join(format!("{}-map", sc.name)));
            let what = format!("{} map of {points} points", sc.name);
            let head = format!("{}: {points} points", sc.name);
            scripts(&a.job, &map_args(&a.map), &out, &what, &head)
        }
        SlurmCmd::Reproduce(a) => {
            check_job(&job(&a.job), a.rep.shard.is_some(), "reproduce")?;
            let sets = squeal_study::reproduce::prepared_sets(a.rep.duration_scale)?;
            check_tasks(a.job.tasks, sets.len(), "sets of the thesis")?;
            let out = a
                .rep
                .out
                .clone()
                .unwrap_or_else(|| PathBuf::from("out").join("reproduce"));
            let what = format!("the thesis's {} sets", sets.len());
            let head = format!("reproduce: {} sets", sets.len());
            scripts(&a.job, &reproduce_args(&a.rep), &out, &what, &head)
        }
        SlurmCmd::Sweep(a) => {
            check_job(&job(&a.job), a.sweep.shard.is_some(), "sweep")?;
            let sc = crate::commands::simulate::resolve(&a.sweep.scenario)?;
            let p = squeal_study::map::parse_axis(&a.sweep.param, "--param", false, &sc.model)?;
            if a.job.tasks > p.values.len() {
                return Err(InputError(format!(
                    "--tasks {}: more tasks than the {} values of --param {}",
                    a.job.tasks,
                    p.values.len(),
                    a.sweep.param
                ))
                .into());
            }
            let out = a
                .sweep
                .out
                .clone()
                .unwrap_or_else(|| PathBuf::from("out").join(format!("{}-sweep", sc.name)));
            let what = format!("{} sweep of {} values", sc.name, p.values.len());
            let head = format!("{}: {} values", sc.name, p.values.len());
            scripts(&a.job, &sweep_args(&a.sweep), &out, &what, &head)
        }
    }
}

/// The job's settings as the files layer takes them.
fn job(a: &JobArgs) -> Job {
    Job {
        tasks: a.tasks,
        partition: a.partition.clone(),
        time: a.time.clone(),
        cpus_per_task: a.cpus_per_task,
        jobs: a.jobs.clone(),
    }
}

/// Write (and with `--submit` submit) the scripts of the study `squeal
/// ARGS…`, merged into `out`; `head_line` starts the terminal's summary.
fn scripts(
    a: &JobArgs,
    args: &[String],
    out: &Path,
    what: &str,
    head_line: &str,
) -> Result<(), RunError> {
    let exe = std::env::current_exe()
        .map_err(|e| RunError::Io(format!("cannot find the squeal executable: {e}")))?;
    let program = [exe.to_string_lossy().into_owned()];
    let s = write_scripts(&job(a), &program, args, out, what, &[])?;
    let n = a.tasks;
    crate::outln!(
        "{head_line} in {n} array tasks; scripts: {} and {}",
        s.array.display(),
        s.merge.display()
    );
    if !a.submit {
        crate::outln!("submit: {}", s.submit_line());
        crate::outln!("rerun task K alone: {}", s.rerun_line());
        return Ok(());
    }
    let (id, mid) = submit(&s)?;
    crate::outln!("submitted: array job {id}, merge job {mid} (after the array succeeds)");
    crate::outln!("merged {}: {}", args[0], s.out.display());
    Ok(())
}
