//! The job scripts of a sharded study on a SLURM cluster (`squeal slurm
//! map|reproduce|sweep`, Python's `squeal.slurm`): a job array that computes
//! the study in N shards and a merge job that depends on it.
//!
//! Writes into the jobs folder (default `OUT-slurm`):
//! - `array.sh`: `#SBATCH --array=0-(N-1)`; task K runs the study's command
//!   (`squeal map … --shard K/N --out JOBS/shard-K/map`; `reproduce`:
//!   `…/reproduce`) with `RAYON_NUM_THREADS` set to `SLURM_CPUS_PER_TASK`;
//!   its log is `JOBS/shard-K.log`. Each shard has a parent folder of its
//!   own: staging removes leftovers of dead processes by PID in the parent
//!   folder, and PIDs of other nodes mean nothing here;
//! - `merge.sh`: `squeal merge JOBS/shard-{0..N-1}/map --out OUT` (or
//!   `…/reproduce`), log `JOBS/merge.log`.
//!
//! [`submit`] runs `sbatch --parsable array.sh`, then `sbatch --parsable
//! --dependency=afterok:ID merge.sh`. Task K alone is rerun with `sbatch
//! --array=K JOBS/array.sh` (then `sbatch JOBS/merge.sh`).

use crate::{RunError, Staging};
use squeal_study::scenario::InputError;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The job array's settings, the same for every study.
#[derive(Debug, Clone, Default)]
pub struct Job {
    /// Number of array tasks (shards).
    pub tasks: usize,
    /// SLURM partition (default: the cluster's default).
    pub partition: Option<String>,
    /// Time limit of each task, in SLURM's format (e.g. 2:00:00).
    pub time: Option<String>,
    /// CPUs of each task; squeal's threads follow SLURM_CPUS_PER_TASK.
    pub cpus_per_task: Option<usize>,
    /// Folder for the scripts, the shards and the logs (default: OUT-slurm).
    pub jobs: Option<PathBuf>,
}

/// The scripts written, in their committed jobs folder.
#[derive(Debug, Clone)]
pub struct Scripts {
    /// The jobs folder.
    pub jobs: PathBuf,
    /// `array.sh`.
    pub array: PathBuf,
    /// `merge.sh`.
    pub merge: PathBuf,
    /// The merged study's output folder (absolute).
    pub out: PathBuf,
}

impl Scripts {
    /// The shell line that submits both jobs by hand.
    pub fn submit_line(&self) -> String {
        format!(
            "ARRAY=$(sbatch --parsable {}) && sbatch --dependency=afterok:$ARRAY {}",
            quoted(&self.array),
            quoted(&self.merge)
        )
    }

    /// The shell line that reruns task K alone.
    pub fn rerun_line(&self) -> String {
        format!("sbatch --array=K {}", quoted(&self.array))
    }
}

fn quoted(p: &Path) -> String {
    sh(&p.to_string_lossy())
}

/// `s` quoted for a POSIX shell.
pub fn sh(s: &str) -> String {
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

/// Run `sbatch ARGS…` and return the job id it prints (`--parsable`).
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

/// Submit both scripts: the array, then the merge after the array succeeds.
/// Returns (array job id, merge job id).
pub fn submit(s: &Scripts) -> Result<(String, String), RunError> {
    let id = sbatch(&["--parsable", &s.array.to_string_lossy()])?;
    let dep = format!("--dependency=afterok:{id}");
    let mid = sbatch(&["--parsable", &dep, &s.merge.to_string_lossy()])?;
    Ok((id, mid))
}

/// The job's settings checked, and `--shard` refused (each task computes
/// its own): bad input names the flag and its value.
pub fn check_job(job: &Job, shard: bool, cmd: &str) -> Result<(), RunError> {
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
pub fn check_tasks(tasks: usize, units: usize, what: &str) -> Result<(), RunError> {
    if tasks > units {
        return Err(InputError(format!(
            "--tasks {tasks}: more tasks than the {units} {what}"
        ))
        .into());
    }
    Ok(())
}

/// Write `array.sh` and `merge.sh` for the study `PROGRAM… ARGS…`
/// (`program`: the squeal executable, or Python running squeal; `args[0]`
/// is the study's command, which also names each task's shard folder
/// `JOBS/shard-K/CMD`), merged into `out` by `PROGRAM… merge`. `extra`
/// files (a scenario the tasks read) are written into the jobs folder too;
/// an argument `@NAME` naming one of them becomes its path there.
pub fn write_scripts(
    a: &Job,
    program: &[String],
    args: &[String],
    out: &Path,
    what: &str,
    extra: &[(&str, &str)],
) -> Result<Scripts, RunError> {
    let cmd = args.first().map_or("map", String::as_str);
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
    let cwd = std::env::current_dir()
        .map_err(|e| RunError::Io(format!("cannot read the current folder: {e}")))?;
    let p = |p: &Path| sh(&p.to_string_lossy());
    let exe: Vec<String> = program.iter().map(|s| sh(s)).collect();
    let exe = exe.join(" ");
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
    // `@NAME` of an extra file: that file in the jobs folder.
    let study: Vec<String> = args
        .iter()
        .map(|a| match a.strip_prefix('@') {
            Some(name) if extra.iter().any(|(n, _)| *n == name) => jobs.join(name),
            _ => PathBuf::from(a),
        })
        .map(|a| sh(&a.to_string_lossy()))
        .collect();
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
        exe,
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
        exe,
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
    for (name, text) in extra {
        let path = stage.path(name);
        std::fs::write(&path, text)
            .map_err(|e| RunError::Io(format!("cannot write {}: {e}", path.display())))?;
    }
    let jobs = stage.commit()?;
    Ok(Scripts {
        array: jobs.join("array.sh"),
        merge: jobs.join("merge.sh"),
        jobs,
        out,
    })
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
