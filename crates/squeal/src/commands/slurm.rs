//! `squeal slurm map|reproduce|sweep … --tasks N [--partition P] [--time T]
//! [--cpus-per-task C] [--jobs DIR] [--submit]`: a SLURM job array that
//! computes a map (or the thesis's 40 sets) in N shards, and a merge job
//! that depends on it.
//!
//! Writes into the jobs folder (default `OUT-slurm`):
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
use crate::run::{RunError, Staging};
use clap::{Args, Subcommand};
use squeal_study::scenario::InputError;
use std::path::{Path, PathBuf};
use std::process::Command;

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

/// `s` quoted for a POSIX shell.
fn sh(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c))
    {
        return s.to_string();
    }
    format!("'{}'", s.replace('\'', "'\\''"))
}

fn abs(p: &Path) -> Result<PathBuf, RunError> {
    if p.is_absolute() {
        return Ok(p.to_path_buf());
    }
    let cwd = std::env::current_dir()
        .map_err(|e| RunError::Io(format!("cannot read the current folder: {e}")))?;
    Ok(cwd.join(p))
}

/// Most CPUs a task may ask for: no node has more.
pub const MAX_CPUS_PER_TASK: usize = 4096;

/// A partition for the `#SBATCH` line: a name or a comma-separated list of
/// names, of letters, digits, `_`, `-` and `.` (what SLURM's partition
/// names are made of); anything else is refused, so nothing but the one
/// directive reaches the script.
fn partition(v: &Option<String>) -> Result<(), RunError> {
    match v {
        Some(s)
            if s.is_empty()
                || !s
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "_-.,".contains(c)) =>
        {
            Err(InputError(format!(
                "--partition {s:?}: not a partition name (letters, digits, '_', '-', '.', comma-separated)"
            ))
            .into())
        }
        _ => Ok(()),
    }
}

/// A time limit in one of SLURM's formats (`MM`, `MM:SS`, `HH:MM:SS`,
/// `D-HH`, `D-HH:MM`, `D-HH:MM:SS`, or `UNLIMITED`/`INFINITE`); anything
/// else is refused.
fn time_limit(v: &Option<String>) -> Result<(), RunError> {
    let Some(s) = v else { return Ok(()) };
    let numbers = |t: &str, most: usize| {
        let parts: Vec<&str> = t.split(':').collect();
        parts.len() <= most
            && parts
                .iter()
                .all(|p| !p.is_empty() && p.len() <= 9 && p.chars().all(|c| c.is_ascii_digit()))
    };
    let ok = matches!(s.to_ascii_lowercase().as_str(), "unlimited" | "infinite")
        || match s.split_once('-') {
            Some((days, rest)) => numbers(days, 1) && numbers(rest, 3),
            None => numbers(s, 3),
        };
    if ok {
        Ok(())
    } else {
        Err(InputError(format!(
            "--time {s:?}: not a SLURM time limit (MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS or UNLIMITED)"
        ))
        .into())
    }
}

/// A path for an `#SBATCH` line. SLURM reads those lines itself, one line
/// each, not through a shell: a control character (a newline would start a
/// new directive or a command), a quote or a backslash (which its option
/// parser interprets) is refused, naming what supplied the path; the
/// path is then single-quoted (it may hold spaces). With a `file` (a log
/// file name, which may use SLURM's patterns such as `%a`), the path is a
/// folder whose own `%` are escaped as `%%` and `file` is joined to it.
fn sbatch_path(what: &str, p: &Path, file: Option<&str>) -> Result<String, RunError> {
    let s = p.to_string_lossy();
    if let Some(c) = s.chars().find(|c| c.is_control() || "'\"\\".contains(*c)) {
        return Err(InputError(format!(
            "{what} {}: holds {c:?}, which a SLURM script's #SBATCH line cannot carry; choose a folder without it",
            s.escape_debug()
        ))
        .into());
    }
    Ok(match file {
        Some(f) => format!("'{}/{f}'", s.replace('%', "%%")),
        None => format!("'{s}'"),
    })
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

fn sbatch(args: &[&str]) -> Result<String, RunError> {
    let out = Command::new("sbatch")
        .args(args)
        .output()
        .map_err(|e| RunError::Io(format!("cannot run sbatch: {e}")))?;
    if !out.status.success() {
        return Err(RunError::Io(format!(
            "sbatch {} failed: {}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr).trim()
        )));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    // --parsable prints `ID` or `ID;CLUSTER`.
    let id = text.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        return Err(RunError::Io(format!(
            "sbatch printed no job id: {}",
            text.trim()
        )));
    }
    Ok(id)
}

/// Run the command.
pub fn run(cmd: SlurmCmd) -> Result<(), RunError> {
    match cmd {
        SlurmCmd::Map(a) => {
            check_job(&a.job, a.map.shard.is_some(), "map")?;
            let (sc, x, y) = prepare(&a.map)?;
            let points = x.values.len() * y.values.len();
            check_tasks(a.job.tasks, points, "points of the map")?;
            let out = a
                .map
                .out
                .clone()
                .unwrap_or_else(|| PathBuf::from("out").join(format!("{}-map", sc.name)));
            let what = format!("{} map of {points} points", sc.name);
            let head = format!("{}: {points} points", sc.name);
            scripts(&a.job, "map", &map_args(&a.map), &out, &what, &head)
        }
        SlurmCmd::Reproduce(a) => {
            check_job(&a.job, a.rep.shard.is_some(), "reproduce")?;
            let sets = squeal_study::reproduce::prepared_sets(a.rep.duration_scale)?;
            check_tasks(a.job.tasks, sets.len(), "sets of the thesis")?;
            let out = a
                .rep
                .out
                .clone()
                .unwrap_or_else(|| PathBuf::from("out").join("reproduce"));
            let what = format!("the thesis's {} sets", sets.len());
            let head = format!("reproduce: {} sets", sets.len());
            scripts(
                &a.job,
                "reproduce",
                &reproduce_args(&a.rep),
                &out,
                &what,
                &head,
            )
        }
        SlurmCmd::Sweep(a) => {
            check_job(&a.job, a.sweep.shard.is_some(), "sweep")?;
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
            scripts(&a.job, "sweep", &sweep_args(&a.sweep), &out, &what, &head)
        }
    }
}

fn check_job(job: &JobArgs, shard: bool, cmd: &str) -> Result<(), RunError> {
    if shard {
        return Err(InputError(format!(
            "--shard: not with `squeal slurm {cmd}` (each array task computes its own shard)"
        ))
        .into());
    }
    if job.tasks == 0 {
        return Err(InputError("--tasks 0: need at least 1 task".into()).into());
    }
    if job.cpus_per_task == Some(0) {
        return Err(InputError("--cpus-per-task 0: need at least 1 CPU".into()).into());
    }
    if let Some(c) = job.cpus_per_task.filter(|c| *c > MAX_CPUS_PER_TASK) {
        return Err(InputError(format!(
            "--cpus-per-task {c}: more than the {MAX_CPUS_PER_TASK} CPUs any node has"
        ))
        .into());
    }
    partition(&job.partition)?;
    time_limit(&job.time)
}

/// `--tasks` above the number of shards there are to compute is refused,
/// naming the bound.
fn check_tasks(tasks: usize, units: usize, what: &str) -> Result<(), RunError> {
    if tasks > units {
        return Err(InputError(format!(
            "--tasks {tasks}: more tasks than the {units} {what}"
        ))
        .into());
    }
    Ok(())
}

/// Write (and with `--submit` submit) `array.sh` and `merge.sh` for the
/// study `squeal ARGS…` (`args[0]` is the command, which also names each
/// task's shard folder `JOBS/shard-K/CMD`), merged into `out`.
fn scripts(
    a: &JobArgs,
    cmd: &str,
    args: &[String],
    out: &Path,
    what: &str,
    head_line: &str,
) -> Result<(), RunError> {
    let out = abs(out)?;
    let jobs = abs(&a.jobs.clone().unwrap_or_else(|| {
        let mut s = out.clone().into_os_string();
        s.push("-slurm");
        PathBuf::from(s)
    }))?;
    let flag = if a.jobs.is_some() {
        "--jobs"
    } else {
        "jobs folder (default --jobs)"
    };
    // Checked before any work (nothing is written if it would fail).
    crate::staging::check_dest_as(flag, &jobs)?;
    let exe = std::env::current_exe()
        .map_err(|e| RunError::Io(format!("cannot find the squeal executable: {e}")))?;
    let cwd = std::env::current_dir()
        .map_err(|e| RunError::Io(format!("cannot read the current folder: {e}")))?;
    let p = |p: &Path| sh(&p.to_string_lossy());
    let n = a.tasks;
    let mut head = String::from("#!/bin/bash\n");
    let mut common = format!(
        "#SBATCH --chdir={}\n",
        sbatch_path("the current folder", &cwd, None)?
    );
    if let Some(part) = &a.partition {
        common.push_str(&format!("#SBATCH --partition={part}\n"));
    }
    if let Some(t) = &a.time {
        common.push_str(&format!("#SBATCH --time={t}\n"));
    }
    head.push_str(&format!(
        "# squeal {}: {what} in {n} shards\n",
        env!("CARGO_PKG_VERSION"),
    ));
    let study: Vec<String> = args.iter().map(|s| sh(s)).collect();
    let mut array = head.clone();
    array.push_str(&format!(
        "#SBATCH --job-name=squeal-{cmd}\n#SBATCH --array=0-{}\n",
        n - 1
    ));
    if let Some(c) = a.cpus_per_task {
        array.push_str(&format!("#SBATCH --cpus-per-task={c}\n"));
    }
    array.push_str(&format!(
        "#SBATCH --output={}\n{common}",
        sbatch_path(flag, &jobs, Some("shard-%a.log"))?
    ));
    array.push_str(&format!(
        "set -euo pipefail\n# squeal's threads: the task's CPUs\nexport RAYON_NUM_THREADS=\"${{SLURM_CPUS_PER_TASK:-1}}\"\n\
         K=\"$SLURM_ARRAY_TASK_ID\"\n\
         exec {} {} --shard \"$K/{n}\" --out {}/shard-\"$K\"/{cmd}\n",
        p(&exe),
        study.join(" "),
        p(&jobs)
    ));
    let mut merge = head;
    merge.push_str(&format!(
        "#SBATCH --job-name=squeal-merge\n#SBATCH --output={}\n{common}",
        sbatch_path(flag, &jobs, Some("merge.log"))?
    ));
    merge.push_str(&format!(
        "set -euo pipefail\nexec {} merge {}/shard-{{0..{}}}/{cmd} --out {}\n",
        p(&exe),
        p(&jobs),
        n - 1,
        p(&out)
    ));
    let stage = Staging::new_as(flag, &jobs)?;
    for (name, text) in [("array.sh", &array), ("merge.sh", &merge)] {
        let path = stage.path(name);
        std::fs::write(&path, text)
            .map_err(|e| RunError::Io(format!("cannot write {}: {e}", path.display())))?;
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755));
        }
    }
    let jobs = stage.commit()?;
    let (arr, mer) = (jobs.join("array.sh"), jobs.join("merge.sh"));
    crate::outln!(
        "{head_line} in {n} array tasks; scripts: {} and {}",
        arr.display(),
        mer.display()
    );
    if !a.submit {
        crate::outln!(
            "submit: ARRAY=$(sbatch --parsable {}) && sbatch --dependency=afterok:$ARRAY {}",
            p(&arr),
            p(&mer)
        );
        crate::outln!("rerun task K alone: sbatch --array=K {}", p(&arr));
        return Ok(());
    }
    let id = sbatch(&["--parsable", &arr.to_string_lossy()])?;
    let dep = format!("--dependency=afterok:{id}");
    let mid = sbatch(&["--parsable", &dep, &mer.to_string_lossy()])?;
    crate::outln!("submitted: array job {id}, merge job {mid} (after the array succeeds)");
    crate::outln!("merged {cmd}: {}", out.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_quoting_keeps_words_whole() {
        assert_eq!(sh("V=0.5:20:5"), "V=0.5:20:5");
        assert_eq!(sh("my file"), "'my file'");
        assert_eq!(sh("it's"), "'it'\\''s'");
        assert_eq!(sh(""), "''");
    }
}
